#include "server/haptics/texture_map.h"

#include <cmath>

#include "absl/strings/str_cat.h"
#include "server/estimate/roughness.h"

namespace surfmap::haptics {
namespace {

absl::Status CheckSize(const char* name, size_t size, size_t n, bool optional) {
  if (size == n || (optional && size == 0)) return absl::OkStatus();
  return absl::InvalidArgumentError(
      absl::StrCat(name, ": ", size, " values for ", n, " vertices", optional ? " (or none)" : ""));
}

absl::Status CheckNotInfinite(const char* name, const std::vector<double>& values) {
  for (size_t i = 0; i < values.size(); ++i) {
    if (std::isinf(values[i])) return absl::InvalidArgumentError(absl::StrCat(name, "[", i, "] is infinite"));
  }
  return absl::OkStatus();
}

}  // namespace

absl::Status ValidateTextureMap(const TextureMap& map) {
  const size_t n = map.positions.size();
  if (n == 0) return absl::InvalidArgumentError("texture map has no vertices");
  if (map.triangles.empty()) return absl::InvalidArgumentError("texture map has no triangles");
  if (!std::isfinite(map.grid_step_mm) || map.grid_step_mm <= 0) {
    return absl::InvalidArgumentError(absl::StrCat("grid_step_mm must be finite and > 0, got ", map.grid_step_mm));
  }
  for (size_t v = 0; v < n; ++v) {
    if (!map.positions[v].allFinite()) return absl::InvalidArgumentError(absl::StrCat("positions[", v, "] is not finite"));
  }
  if (!map.normals.empty()) {
    if (map.normals.size() != n) return CheckSize("normals", map.normals.size(), n, true);
    for (size_t v = 0; v < n; ++v) {
      if (!map.normals[v].allFinite()) return absl::InvalidArgumentError(absl::StrCat("normals[", v, "] is not finite"));
    }
  }
  for (size_t t = 0; t < map.triangles.size(); ++t) {
    for (int c : map.triangles[t]) {
      if (c < 0 || static_cast<size_t>(c) >= n) {
        return absl::InvalidArgumentError(absl::StrCat("triangles[", t, "] has vertex ", c, " outside 0..", n - 1));
      }
    }
  }
  if (absl::Status s = CheckSize("mu", map.mu.size(), n, false); !s.ok()) return s;
  if (absl::Status s = CheckSize("mu_std", map.mu_std.size(), n, false); !s.ok()) return s;
  for (auto [name, values] : {std::pair{"sigma", &map.sigma}, std::pair{"a1", &map.a1}, std::pair{"a2", &map.a2},
                              std::pair{"boundary_probability", &map.boundary_probability}}) {
    if (absl::Status s = CheckSize(name, values->size(), n, true); !s.ok()) return s;
  }
  for (auto [name, values] : {std::pair{"mu", &map.mu}, std::pair{"mu_std", &map.mu_std},
                              std::pair{"sigma", &map.sigma}, std::pair{"a1", &map.a1}, std::pair{"a2", &map.a2},
                              std::pair{"reflection", &map.reflection},
                              std::pair{"boundary_probability", &map.boundary_probability}}) {
    if (absl::Status s = CheckNotInfinite(name, *values); !s.ok()) return s;
  }
  for (size_t v = 0; v < map.sigma.size(); ++v) {
    if (map.sigma[v] < 0) return absl::InvalidArgumentError(absl::StrCat("sigma[", v, "] is negative"));
  }
  if (map.ar_order < 0 || map.ar_order > 20) {
    return absl::InvalidArgumentError(absl::StrCat("ar_order must be in 0..20, got ", map.ar_order));
  }
  if (map.reflection.size() != n * static_cast<size_t>(map.ar_order)) {
    return absl::InvalidArgumentError(absl::StrCat("reflection: ", map.reflection.size(), " values, expected ",
                                                   n, " vertices x order ", map.ar_order));
  }
  if (map.ar_order > 0 && map.sigma.size() != n) {
    return absl::InvalidArgumentError("reflection coefficients without a sigma per vertex");
  }
  if (absl::Status s = CheckSize("region", map.region.size(), n, true); !s.ok()) return s;
  const int regions = static_cast<int>(map.regions.size());
  for (size_t v = 0; v < map.region.size(); ++v) {
    if (map.region[v] < -1 || map.region[v] >= regions) {
      return absl::InvalidArgumentError(
          absl::StrCat("region[", v, "] = ", map.region[v], " is outside -1..", regions - 1));
    }
  }
  return absl::OkStatus();
}

void FillReflectionFromAr(TextureMap& map) {
  const size_t n = map.positions.size();
  if (map.a1.size() != n || map.a2.size() != n) return;
  map.ar_order = 2;
  map.reflection.assign(2 * n, 0.0);
  for (size_t v = 0; v < n; ++v) {
    const bool known = std::isfinite(map.a1[v]) && std::isfinite(map.a2[v]) &&
                       (map.sigma.size() != n || (std::isfinite(map.sigma[v]) && map.sigma[v] > 0));
    if (!known) continue;
    const std::vector<double> k = ArToReflection({map.a1[v], map.a2[v]});
    map.reflection[2 * v] = k[0];
    map.reflection[2 * v + 1] = k[1];
  }
}

std::vector<std::string> PerVertexAttributeNames(const TextureMap& map) {
  std::vector<std::string> names = {"mu", "mu_std"};
  if (!map.sigma.empty()) names.push_back("sigma");
  if (!map.a1.empty()) names.push_back("a1");
  if (!map.a2.empty()) names.push_back("a2");
  for (int j = 0; j < map.ar_order; ++j) names.push_back(absl::StrCat("k", j + 1));
  if (!map.region.empty()) names.push_back("region");
  if (!map.boundary_probability.empty()) names.push_back("boundary_probability");
  return names;
}

}  // namespace surfmap::haptics
