// The true surface of an object whose sampling control mesh was simplified
// from a dense mesh (a scan): the dense mesh itself, piecewise flat, with
// smooth (area-weighted, interpolated) vertex normals. Sites, drag paths and
// the map's positions are projected onto it, so what the rig is sent lies on
// the object it touches, not on the coarse mesh's Loop surface.
#pragma once

#include <functional>
#include <vector>

#include <Eigen/Core>
#include "server/mesh/control_mesh.h"
#include "server/mesh/mesh_locator.h"

namespace surfmap {

class DenseSurface {
 public:
  // `mesh` must be valid (ValidateControlMesh).
  explicit DenseSurface(const ControlMesh& mesh);

  // Replaces `position` by its closest point on the mesh and `normal` by the
  // interpolated vertex normal there (unit, outward by the winding).
  void Project(Eigen::Vector3d& position, Eigen::Vector3d& normal) const;

  // LoopSurface::Create's projection onto this surface (which must outlive the call).
  std::function<void(Eigen::Vector3d&, Eigen::Vector3d&)> Projection() const {
    return [this](Eigen::Vector3d& p, Eigen::Vector3d& n) { Project(p, n); };
  }

 private:
  MeshLocator locator_;
  std::vector<Eigen::Vector3d> vertex_normals_;
};

}  // namespace surfmap
