// The true surface of an object whose sampling control mesh was simplified
// from a dense mesh (a scan): the dense mesh itself, piecewise flat, with
// smooth (area-weighted, interpolated) vertex normals. Sites, drag paths and
// the map's positions are projected onto it, so what the rig is sent lies on
// the object it touches, not on the coarse mesh's Loop surface.
#pragma once

#include <array>
#include <functional>
#include <vector>

#include <Eigen/Core>
#include "server/mesh/control_mesh.h"
#include "server/mesh/mesh_locator.h"

namespace surfmap {

class DenseSurface {
 public:
  // `mesh` must be valid (ValidateControlMesh). A vertex's normal is smoothed
  // over the faces around it whose normals lie within `crease_angle_deg` of
  // the face it is read for: 180 (a scan) smooths over all of them; a CAD
  // part's sharp edges keep each face's own normal on its side
  // (kCadCreaseAngleDeg).
  explicit DenseSurface(const ControlMesh& mesh, double crease_angle_deg = 180.0);

  // Replaces `position` by its closest point on the mesh and `normal` by the
  // interpolated vertex normal there (unit, outward by the winding).
  void Project(Eigen::Vector3d& position, Eigen::Vector3d& normal) const;

  // LoopSurface::Create's projection onto this surface (which must outlive the call).
  std::function<void(Eigen::Vector3d&, Eigen::Vector3d&)> Projection() const {
    return [this](Eigen::Vector3d& p, Eigen::Vector3d& n) { Project(p, n); };
  }

 private:
  MeshLocator locator_;
  std::vector<Eigen::Vector3d> vertex_normals_;  // smooth everywhere (crease 180)
  // With a crease below 180: each triangle's corners' normals, smoothed only
  // over faces within the crease of it.
  std::vector<std::array<Eigen::Vector3d, 3>> corner_normals_;
};

// A CAD export's facets meet at sharp edges (a box's 90 degrees, a chamfer's
// 45) or bend gently across a tessellated curve (a 16-segment cylinder's 22.5
// degrees): normals are smoothed below this angle between faces and kept
// apart above it.
inline constexpr double kCadCreaseAngleDeg = 30.0;

}  // namespace surfmap
