#include "server/mesh/dense_surface.h"

#include <Eigen/Geometry>

namespace surfmap {

DenseSurface::DenseSurface(const ControlMesh& mesh)
    : locator_(mesh.positions, mesh.triangles), vertex_normals_(mesh.positions.size(), Eigen::Vector3d::Zero()) {
  // Area-weighted: the cross product's length is twice the face's area.
  for (const auto& t : mesh.triangles) {
    const Eigen::Vector3d& a = mesh.positions[t[0]];
    const Eigen::Vector3d n = (mesh.positions[t[1]] - a).cross(mesh.positions[t[2]] - a);
    for (int v : t) vertex_normals_[v] += n;
  }
  for (Eigen::Vector3d& n : vertex_normals_) {
    const double norm = n.norm();
    n = norm > 0 ? Eigen::Vector3d(n / norm) : Eigen::Vector3d::UnitZ();
  }
}

void DenseSurface::Project(Eigen::Vector3d& position, Eigen::Vector3d& normal) const {
  const SurfacePoint hit = locator_.Closest(position);
  if (hit.triangle < 0) return;
  const auto& t = locator_.triangles()[hit.triangle];
  const Eigen::Vector3d n = hit.barycentric[0] * vertex_normals_[t[0]] + hit.barycentric[1] * vertex_normals_[t[1]] +
                            hit.barycentric[2] * vertex_normals_[t[2]];
  position = hit.position;
  const double norm = n.norm();
  normal = norm > 1e-12 ? Eigen::Vector3d(n / norm) : hit.normal;
}

}  // namespace surfmap
