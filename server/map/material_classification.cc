#include "server/map/material_classification.h"

#include <cmath>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"

namespace surfmap {

absl::StatusOr<std::vector<int>> ClassifyNearestMaterial(std::span<const double> mu,
                                                         std::span<const double> material_mus) {
  if (material_mus.empty()) return absl::InvalidArgumentError("ClassifyNearestMaterial: no materials given");
  for (size_t m = 0; m < material_mus.size(); ++m) {
    if (!std::isfinite(material_mus[m])) {
      return absl::InvalidArgumentError(absl::StrCat("ClassifyNearestMaterial: material ", m, " has mu ",
                                                     material_mus[m], ", not a finite number"));
    }
  }
  std::vector<int> out(mu.size(), 0);
  for (size_t i = 0; i < mu.size(); ++i) {
    if (!std::isfinite(mu[i])) {
      return absl::InvalidArgumentError(
          absl::StrCat("ClassifyNearestMaterial: value ", i, " is ", mu[i], ", not a finite number"));
    }
    double best = std::abs(mu[i] - material_mus[0]);
    for (size_t m = 1; m < material_mus.size(); ++m) {
      const double d = std::abs(mu[i] - material_mus[m]);
      if (d < best) {
        best = d;
        out[i] = static_cast<int>(m);
      }
    }
  }
  return out;
}

}  // namespace surfmap
