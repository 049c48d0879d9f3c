#include "clients/render/map_mesh.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Geometry>
#include "absl/strings/str_cat.h"

namespace surfmap {
namespace {

bool AllFinite(const Eigen::Vector3d& v) { return v.allFinite(); }

}  // namespace

absl::Status ValidateMapMesh(const MapMesh& mesh) {
  const size_t n = mesh.positions.size();
  if (n == 0) return absl::InvalidArgumentError("map mesh has no vertices");
  if (mesh.triangles.empty()) return absl::InvalidArgumentError("map mesh has no triangles");
  for (size_t i = 0; i < n; ++i) {
    if (!AllFinite(mesh.positions[i])) {
      return absl::InvalidArgumentError(absl::StrCat("map mesh vertex ", i, " has a non-finite position"));
    }
  }
  if (!mesh.normals.empty()) {
    if (mesh.normals.size() != n) {
      return absl::InvalidArgumentError(
          absl::StrCat("map mesh has ", mesh.normals.size(), " normals for ", n, " vertices"));
    }
    for (size_t i = 0; i < n; ++i) {
      if (!AllFinite(mesh.normals[i])) {
        return absl::InvalidArgumentError(absl::StrCat("map mesh vertex ", i, " has a non-finite normal"));
      }
    }
  }
  if (mesh.values.size() != n) {
    return absl::InvalidArgumentError(
        absl::StrCat("map mesh has ", mesh.values.size(), " values for ", n, " vertices"));
  }
  for (size_t i = 0; i < n; ++i) {
    if (std::isinf(mesh.values[i])) {
      return absl::InvalidArgumentError(absl::StrCat("map mesh vertex ", i, " has an infinite value"));
    }
  }
  if (!mesh.uncertainties.empty() && mesh.uncertainties.size() != n) {
    return absl::InvalidArgumentError(
        absl::StrCat("map mesh has ", mesh.uncertainties.size(), " uncertainties for ", n, " vertices"));
  }
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    for (int k = 0; k < 3; ++k) {
      const int v = mesh.triangles[t][k];
      if (v < 0 || static_cast<size_t>(v) >= n) {
        return absl::InvalidArgumentError(absl::StrCat("map mesh triangle ", t, " corner ", k, " refers to vertex ",
                                                       v, ", outside 0..", n - 1));
      }
    }
  }
  return absl::OkStatus();
}

std::vector<Eigen::Vector3d> ComputeVertexNormals(const MapMesh& mesh) {
  std::vector<Eigen::Vector3d> normals(mesh.positions.size(), Eigen::Vector3d::Zero());
  for (const auto& t : mesh.triangles) {
    const Eigen::Vector3d& a = mesh.positions[t[0]];
    const Eigen::Vector3d& b = mesh.positions[t[1]];
    const Eigen::Vector3d& c = mesh.positions[t[2]];
    const Eigen::Vector3d area_normal = (b - a).cross(c - a);  // |.| = 2 * area: area weighting
    for (int v : t) normals[v] += area_normal;
  }
  for (auto& nrm : normals) {
    const double len = nrm.norm();
    nrm = len > 0 ? Eigen::Vector3d(nrm / len) : Eigen::Vector3d::UnitZ();
  }
  return normals;
}

std::array<double, 2> FiniteValueRange(const std::vector<double>& values) {
  double lo = std::numeric_limits<double>::infinity();
  double hi = -lo;
  for (double v : values) {
    if (!std::isfinite(v)) continue;
    lo = std::min(lo, v);
    hi = std::max(hi, v);
  }
  if (!(lo <= hi)) return {0.0, 1.0};
  return {lo, hi};
}

}  // namespace surfmap
