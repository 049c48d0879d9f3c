// The per-vertex quantities of a texture map by name, for pictures (`surfmap
// map get --format png --quantity ...`) and scripts: their values and a
// colour-bar title with the unit.
#pragma once

#include <string_view>
#include <vector>

#include "absl/status/statusor.h"
#include "server/haptics/texture_map.h"

namespace surfmap::haptics {

enum class MapQuantity { kMu, kMuStd, kSigma, kA1, kA2, kRegion, kBoundaryProbability };

// "mu", "mu_std", "sigma", "a1", "a2", "region", "boundary_probability".
// Errors: INVALID_ARGUMENT listing the names.
absl::StatusOr<MapQuantity> ParseMapQuantity(std::string_view name);
std::string_view MapQuantityName(MapQuantity quantity);

// The colour-bar title in capitals with the unit: "MU", "MU STD", "SIGMA (N)",
// "A1", "A2", "REGION", "BOUNDARY PROB".
std::string_view MapQuantityTitle(MapQuantity quantity);

// One value per vertex; NaN where unknown (no region: NaN). Errors:
// FAILED_PRECONDITION when the map does not carry the quantity (e.g. sigma
// of a friction-only job), naming it.
absl::StatusOr<std::vector<double>> MapQuantityValues(const TextureMap& map, MapQuantity quantity);

}  // namespace surfmap::haptics
