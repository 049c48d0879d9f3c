#include "server/haptics/export/texture_map_proto.h"

#include <cmath>

#include "absl/strings/str_cat.h"

namespace surfmap::haptics {

namespace pb = ::surfmap::v1;

double GridStepOf(const pb::MapLevel& map) {
  for (const pb::Sample& s : map.samples()) {
    const double step = s.fit().roughness().grid_step_mm();
    if (std::isfinite(step) && step > 0) return step;
  }
  return 0.1;
}

absl::StatusOr<TextureMap> TextureMapFromResponse(const pb::GetMapResponse& response) {
  const pb::MapLevel& m = response.map();
  const pb::GetMeshResponse& mesh = response.mesh();
  if (mesh.positions_size() == 0) {
    return absl::InvalidArgumentError("the map has no mesh (GetMap with include_mesh)");
  }
  const int n = mesh.positions_size();
  if (mesh.triangle_indices_size() % 3 != 0) {
    return absl::InvalidArgumentError("triangle_indices is not a multiple of 3");
  }
  TextureMap map;
  map.job_id = m.job_id();
  map.level = m.level();
  map.grid_step_mm = GridStepOf(m);
  map.positions.reserve(n);
  for (const pb::Vec3& p : mesh.positions()) map.positions.emplace_back(p.x(), p.y(), p.z());
  if (mesh.normals_size() == n) {
    for (const pb::Vec3& p : mesh.normals()) map.normals.emplace_back(p.x(), p.y(), p.z());
  }
  for (int i = 0; i + 2 < mesh.triangle_indices_size(); i += 3) {
    map.triangles.push_back({mesh.triangle_indices(i), mesh.triangle_indices(i + 1), mesh.triangle_indices(i + 2)});
  }
  // A map without any sample has no per-vertex values yet: unknown everywhere.
  if (m.mu_size() == 0) {
    map.mu.assign(n, std::nan(""));
    map.mu_std.assign(n, std::nan(""));
  } else {
    map.mu.assign(m.mu().begin(), m.mu().end());
    map.mu_std.assign(m.mu_uncertainty().begin(), m.mu_uncertainty().end());
  }
  map.sigma.assign(m.sigma().begin(), m.sigma().end());
  map.a1.assign(m.a1().begin(), m.a1().end());
  map.a2.assign(m.a2().begin(), m.a2().end());
  map.region.assign(m.region().begin(), m.region().end());
  map.boundary_probability.assign(m.boundary_probability().begin(), m.boundary_probability().end());
  for (const pb::MapRegion& r : m.regions()) {
    TextureRegion out;
    out.region = r.region();
    out.mu = r.mu();
    out.mu_se = r.mu_se();
    out.mu_spread = r.mu_spread();
    out.piece_count = r.piece_count();
    out.roughness_piece_count = r.roughness_piece_count();
    out.reflection.assign(r.reflection().begin(), r.reflection().end());
    out.ar_coefficients.assign(r.ar_coefficients().begin(), r.ar_coefficients().end());
    out.sigma = r.sigma();
    out.area_mm2 = r.area_mm2();
    map.regions.push_back(std::move(out));
  }
  for (auto [name, size] : {std::pair{"mu", map.mu.size()}, std::pair{"mu_uncertainty", map.mu_std.size()}}) {
    if (static_cast<int>(size) != n) {
      return absl::InvalidArgumentError(absl::StrCat("map ", name, " has ", size, " values for ", n, " mesh vertices"));
    }
  }
  if (map.sigma.size() == static_cast<size_t>(n) && map.a1.size() == static_cast<size_t>(n) &&
      map.a2.size() == static_cast<size_t>(n)) {
    FillReflectionFromAr(map);
  }
  if (absl::Status s = ValidateTextureMap(map); !s.ok()) return s;
  return map;
}

}  // namespace surfmap::haptics
