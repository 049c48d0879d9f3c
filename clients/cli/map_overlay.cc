#include "clients/cli/map_overlay.h"

#include <cmath>
#include <limits>

namespace surfmap::cli {
namespace {

namespace pb = ::surfmap::v1;

Eigen::Vector3d FromProto(const pb::Vec3& v) { return {v.x(), v.y(), v.z()}; }

int NearestVertex(const MapMesh& mesh, const Eigen::Vector3d& p) {
  int best = -1;
  double best_d2 = std::numeric_limits<double>::infinity();
  for (size_t i = 0; i < mesh.positions.size(); ++i) {
    const double d2 = (mesh.positions[i] - p).squaredNorm();
    if (d2 < best_d2) {
      best_d2 = d2;
      best = static_cast<int>(i);
    }
  }
  return best;
}

}  // namespace

MapMesh MapMeshFromResponse(const pb::GetMapResponse& response) {
  MapMesh mesh;
  for (const pb::Vec3& p : response.mesh().positions()) mesh.positions.push_back(FromProto(p));
  if (response.mesh().normals_size() == response.mesh().positions_size()) {
    for (const pb::Vec3& n : response.mesh().normals()) mesh.normals.push_back(FromProto(n));
  }
  const auto& idx = response.mesh().triangle_indices();
  for (int i = 0; i + 2 < idx.size(); i += 3) mesh.triangles.push_back({idx[i], idx[i + 1], idx[i + 2]});
  const size_t n = mesh.positions.size();
  const pb::MapLevel& map = response.map();
  if (static_cast<size_t>(map.mu_size()) == n) {
    mesh.values.assign(map.mu().begin(), map.mu().end());
  } else {
    mesh.values.assign(n, std::numeric_limits<double>::quiet_NaN());
  }
  if (static_cast<size_t>(map.mu_uncertainty_size()) == n) {
    mesh.uncertainties.assign(map.mu_uncertainty().begin(), map.mu_uncertainty().end());
  }
  return mesh;
}

MapOverlay SampleOverlay(const MapMesh& mesh, const pb::MapLevel& map) {
  MapOverlay overlay;
  if (mesh.positions.empty()) return overlay;
  const std::vector<Eigen::Vector3d> normals = mesh.normals.empty() ? ComputeVertexNormals(mesh) : mesh.normals;
  constexpr int kPathPoints = 12;
  for (const pb::Sample& s : map.samples()) {
    const Eigen::Vector3d start = FromProto(s.position());
    if (!start.allFinite()) continue;
    overlay.sample_points.push_back(start);
    const Eigen::Vector3d direction = FromProto(s.drag_direction());
    const double length = s.segment_length_mm();
    if (!direction.allFinite() || direction.norm() < 1e-9 || !(length > 0) || !std::isfinite(length)) continue;
    const Eigen::Vector3d d = direction.normalized();
    std::vector<Eigen::Vector3d> path;
    for (int k = 0; k < kPathPoints; ++k) {
      Eigen::Vector3d p = start + d * (length * k / (kPathPoints - 1));
      const int v = NearestVertex(mesh, p);
      const Eigen::Vector3d& n = normals[v];
      if (n.allFinite() && n.norm() > 0.5) p -= n * n.dot(p - mesh.positions[v]);
      path.push_back(p);
    }
    overlay.drag_paths.push_back(std::move(path));
  }
  return overlay;
}

}  // namespace surfmap::cli
