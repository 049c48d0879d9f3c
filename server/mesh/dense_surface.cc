#include "server/mesh/dense_surface.h"

#include <cmath>
#include <numbers>

#include <Eigen/Geometry>

namespace surfmap {

DenseSurface::DenseSurface(const ControlMesh& mesh, double crease_angle_deg)
    : locator_(mesh.positions, mesh.triangles), vertex_normals_(mesh.positions.size(), Eigen::Vector3d::Zero()) {
  // Area-weighted: the cross product's length is twice the face's area.
  std::vector<Eigen::Vector3d> face_normals;
  face_normals.reserve(mesh.triangles.size());
  for (const auto& t : mesh.triangles) {
    const Eigen::Vector3d& a = mesh.positions[t[0]];
    const Eigen::Vector3d n = (mesh.positions[t[1]] - a).cross(mesh.positions[t[2]] - a);
    for (int v : t) vertex_normals_[v] += n;
    face_normals.push_back(n);
  }
  for (Eigen::Vector3d& n : vertex_normals_) {
    const double norm = n.norm();
    n = norm > 0 ? Eigen::Vector3d(n / norm) : Eigen::Vector3d::UnitZ();
  }
  if (!(crease_angle_deg < 180.0)) return;

  // Faces around each vertex.
  std::vector<std::vector<int>> around(mesh.positions.size());
  for (int t = 0; t < static_cast<int>(mesh.triangles.size()); ++t) {
    for (int v : mesh.triangles[t]) around[v].push_back(t);
  }
  const double cos_crease = std::cos(crease_angle_deg * std::numbers::pi / 180.0);
  std::vector<Eigen::Vector3d> unit(face_normals.size(), Eigen::Vector3d::Zero());
  for (std::size_t t = 0; t < face_normals.size(); ++t) {
    if (const double norm = face_normals[t].norm(); norm > 0) unit[t] = face_normals[t] / norm;
  }
  // Weighted by each face's angle at the vertex (Thuermer and Wuethrich):
  // a CAD exporter's triangulation is lopsided (a cylinder's quads split
  // one way), and area weights would tilt a cylinder's normals by ~5 degrees.
  auto corner_angle = [&](int u, int v) {
    const auto& tri = mesh.triangles[u];
    const int k = tri[0] == v ? 0 : tri[1] == v ? 1 : 2;
    const Eigen::Vector3d a = mesh.positions[tri[(k + 1) % 3]] - mesh.positions[v];
    const Eigen::Vector3d b = mesh.positions[tri[(k + 2) % 3]] - mesh.positions[v];
    return std::atan2(a.cross(b).norm(), a.dot(b));
  };
  corner_normals_.resize(mesh.triangles.size());
  for (int t = 0; t < static_cast<int>(mesh.triangles.size()); ++t) {
    const Eigen::Vector3d& own = unit[t];
    for (int k = 0; k < 3; ++k) {
      const int v = mesh.triangles[t][k];
      Eigen::Vector3d sum = Eigen::Vector3d::Zero();
      for (int u : around[v]) {
        if (u == t || unit[u].dot(own) >= cos_crease) sum += corner_angle(u, v) * unit[u];
      }
      const double norm = sum.norm();
      corner_normals_[t][k] = norm > 0 ? Eigen::Vector3d(sum / norm) : vertex_normals_[mesh.triangles[t][k]];
    }
  }
}

void DenseSurface::Project(Eigen::Vector3d& position, Eigen::Vector3d& normal) const {
  const SurfacePoint hit = locator_.Closest(position);
  if (hit.triangle < 0) return;
  const auto& t = locator_.triangles()[hit.triangle];
  Eigen::Vector3d n;
  if (corner_normals_.empty()) {
    n = hit.barycentric[0] * vertex_normals_[t[0]] + hit.barycentric[1] * vertex_normals_[t[1]] +
        hit.barycentric[2] * vertex_normals_[t[2]];
  } else {
    const std::array<Eigen::Vector3d, 3>& c = corner_normals_[hit.triangle];
    n = hit.barycentric[0] * c[0] + hit.barycentric[1] * c[1] + hit.barycentric[2] * c[2];
  }
  position = hit.position;
  const double norm = n.norm();
  normal = norm > 1e-12 ? Eigen::Vector3d(n / norm) : hit.normal;
}

}  // namespace surfmap
