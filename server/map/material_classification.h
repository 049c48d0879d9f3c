// Classifying a map into known materials (for evaluating maps against a truth).
#pragma once

#include <span>
#include <vector>

#include "absl/status/statusor.h"

namespace surfmap {

// For each value in `mu`, the index of the material in `material_mus` with the
// nearest mu (ties go to the lower index). Errors (INVALID_ARGUMENT): no
// materials, a non-finite material mu or value (naming its index).
absl::StatusOr<std::vector<int>> ClassifyNearestMaterial(std::span<const double> mu,
                                                         std::span<const double> material_mus);

}  // namespace surfmap
