// A Loop subdivision surface refined uniformly to a maximum level with
// OpenSubdiv (Far::TopologyRefiner, Sdc::SCHEME_LOOP). OpenSubdiv types stay
// inside this module.
//
// Vertex numbering contract (relied on by the planner and the map): the child
// of a vertex keeps its index, so vertex i of level k is vertex i of every
// finer level; the vertices added at level k+1 (one per edge of level k) come
// after them. A sampling site (level, vertex) is therefore also vertex
// `vertex` of the finest level.
#pragma once

#include <array>
#include <memory>
#include <vector>

#include <Eigen/Core>
#include "absl/status/statusor.h"
#include "server/mesh/control_mesh.h"

namespace surfmap {

struct SurfaceLevel {
  std::vector<Eigen::Vector3d> positions;        // refined (not limit) vertex positions
  std::vector<Eigen::Vector3d> limit_positions;  // on the limit surface
  std::vector<Eigen::Vector3d> limit_normals;    // unit, outward (from the limit tangents)
  std::vector<std::array<int, 3>> triangles;
  std::vector<std::array<int, 2>> edges;         // each undirected edge once, lower index first
  std::vector<std::vector<int>> neighbors;       // vertex adjacency, sorted ascending
  // For each edge of this level: the vertex of level+1 that splits it
  // (empty at the finest level).
  std::vector<int> edge_child_vertex;
  // For each vertex of this level (level > 0): the edge of level-1 it splits,
  // or -1 for a vertex that is the child of a vertex of level-1.
  std::vector<int> parent_edge;
};

// The closest point on the finest level's limit mesh (finest triangles with
// limit vertex positions).
struct SurfacePoint {
  int triangle = -1;                        // finest-level triangle
  Eigen::Vector3d barycentric = Eigen::Vector3d::Zero();
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  // interpolated limit normal, unit
  double distance = 0.0;                    // from the query point, mm
};

// A polyline that stays on the surface.
struct SurfacePath {
  std::vector<Eigen::Vector3d> points;   // mm
  std::vector<Eigen::Vector3d> normals;  // unit surface normals at the points
  double length_mm = 0.0;
};

class LoopSurface {
 public:
  // Refines `control` to `max_level` (0..6). Errors: invalid mesh, a level out
  // of range, OpenSubdiv errors (reported by its error callback).
  static absl::StatusOr<std::unique_ptr<LoopSurface>> Create(const ControlMesh& control, int max_level);
  ~LoopSurface();

  int max_level() const;
  const SurfaceLevel& level(int k) const;  // 0 <= k <= max_level()
  const SurfaceLevel& finest() const { return level(max_level()); }

  // Closest point on the finest limit mesh (accelerated; many queries per ms).
  SurfacePoint ClosestPoint(const Eigen::Vector3d& query) const;

  // From `start` (projected onto the surface), walks `length_mm` along the
  // surface in the tangent direction nearest `direction`, re-projecting every
  // `step_mm`. Errors: zero direction, direction along the normal, non-positive
  // length or step.
  absl::StatusOr<SurfacePath> TraceDragPath(const Eigen::Vector3d& start, const Eigen::Vector3d& direction,
                                            double length_mm, double step_mm = 0.25) const;

  // A deterministic tangent drag direction at a finest-level vertex: the world
  // axis least aligned with the normal, projected onto the tangent plane.
  Eigen::Vector3d DefaultDragDirection(int finest_vertex) const;

 private:
  LoopSurface();
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace surfmap
