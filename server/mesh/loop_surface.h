// A Loop subdivision surface refined uniformly to a maximum level with
// OpenSubdiv (Far::TopologyRefiner, Sdc::SCHEME_LOOP). OpenSubdiv types stay
// inside this module.
//
// Vertex numbering contract (relied on by the planner and the map): the child
// of a vertex keeps its index, so vertex i of level k is vertex i of every
// finer level; the vertices added at level k+1 (one per edge of level k) come
// after them. A sampling site (level, vertex) is therefore also vertex
// `vertex` of the finest level. Create checks this against OpenSubdiv's
// refinement tables (an InternalError if it ever failed).
//
// Boundaries: open meshes use OpenSubdiv's VTX_BOUNDARY_EDGE_AND_CORNER rule:
// boundary edges are interpolated and a boundary vertex with a single face is
// a fixed corner (MakeGridPlate triangulates so that plate corners are such
// vertices). A boundary vertex with two or more faces is smoothed along the
// boundary curve.
//
// Thread safety: after Create, every const method may be called concurrently.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

#include <Eigen/Core>
#include "absl/status/statusor.h"
#include "server/mesh/control_mesh.h"

namespace surfmap {

struct SurfaceLevel {
  std::vector<Eigen::Vector3d> positions;        // refined (not limit) vertex positions
  std::vector<Eigen::Vector3d> limit_positions;  // on the limit surface
  std::vector<Eigen::Vector3d> limit_normals;    // unit, outward (from the limit tangents; outward =
                                                 // the side the control triangles wind counter-clockwise)
  std::vector<std::array<int, 3>> triangles;
  // Each undirected edge once, lower index first, in OpenSubdiv's edge order
  // (not sorted), so that edge e's child vertex is positions.size() + e.
  std::vector<std::array<int, 2>> edges;
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

// Refinement output cap: the finest level costs ~250 bytes per triangle with
// its topology, limit data and search tree, so 4M triangles is ~1 GB.
inline constexpr std::int64_t kMaxFinestTriangles = std::int64_t{1} << 22;

// `wanted` (clamped to 0..6), or the finest coarser level whose triangles
// stay within kMaxFinestTriangles: for tools that refine any mesh they are
// given (a 20k-triangle scan to level 3, not 4).
int LevelWithinTriangleLimit(const ControlMesh& control, int wanted);

class LoopSurface {
 public:
  // Refines `control` to `max_level` (0..6). Errors (INVALID_ARGUMENT unless
  // noted): invalid mesh (ValidateControlMesh), a level out of range, a finest
  // level of more than 2^22 triangles (memory guard), OpenSubdiv errors
  // (reported by its error callback; INTERNAL if refinement itself fails).
  // Cost: a 10k-triangle mesh to level 3 takes ~0.3 s of computation plus
  // first-touch of ~150 MB (see loop_surface_benchmark.cc).
  static absl::StatusOr<std::unique_ptr<LoopSurface>> Create(const ControlMesh& control, int max_level);

  // Moves a limit vertex onto the true surface when the control mesh is a
  // simplification of a denser one (dense_surface.h): called with the limit
  // position and unit normal of every finest vertex, which it replaces. The
  // levels' limit positions and normals, closest points and drag paths are
  // then on the true surface; the topology (sites, edges) is the control
  // mesh's.
  using LimitProjection = std::function<void(Eigen::Vector3d& position, Eigen::Vector3d& normal)>;
  static absl::StatusOr<std::unique_ptr<LoopSurface>> Create(const ControlMesh& control, int max_level,
                                                             const LimitProjection& projection);

  // How the control mesh's edges are refined.
  enum class Edges {
    // Loop's smooth rules: the control mesh is a cage the surface lies inside.
    kSmooth,
    // Every control edge infinitely sharp (OpenSubdiv creases): every vertex
    // where three or more edges meet is a corner that stays put, every edge
    // stays a straight line and every face stays flat, so each level lies
    // exactly on the control mesh's own facets (a CAD export's surface).
    kSharp,
  };
  static absl::StatusOr<std::unique_ptr<LoopSurface>> Create(const ControlMesh& control, int max_level,
                                                             const LimitProjection& projection, Edges edges);
  ~LoopSurface();

  int max_level() const;
  const SurfaceLevel& level(int k) const;  // 0 <= k <= max_level(); other k are clamped into range
  const SurfaceLevel& finest() const { return level(max_level()); }

  // Closest point on the finest limit mesh: exact over its triangles, found
  // with a bounding-volume tree (~5 us near the surface at 640k triangles,
  // slower far away from it).
  SurfacePoint ClosestPoint(const Eigen::Vector3d& query) const;

  // From `start` (projected onto the surface), walks `length_mm` along the
  // surface in the tangent direction nearest `direction`, re-projecting every
  // `step_mm` and parallel-transporting the direction (its component along
  // the new normal is removed). The path's polyline length equals length_mm
  // (to 1e-9 relative); points[0] is the projected start.
  // Errors: INVALID_ARGUMENT for a zero or non-finite direction, a direction
  // within ~0.06 degrees of the normal, non-positive or non-finite length or
  // step, more than 1e6 steps; OUT_OF_RANGE when the walk would leave an open
  // mesh across its boundary before length_mm (the message says after how
  // many mm and where; callers may retry in another direction or from
  // another start). Walking along a boundary is allowed.
  absl::StatusOr<SurfacePath> TraceDragPath(const Eigen::Vector3d& start, const Eigen::Vector3d& direction,
                                            double length_mm, double step_mm = 0.25) const;

  // A deterministic tangent drag direction at a finest-level vertex: the world
  // axis least aligned with the normal (x before y before z on ties),
  // projected onto the tangent plane, unit. Zero for a vertex out of range.
  Eigen::Vector3d DefaultDragDirection(int finest_vertex) const;

 private:
  LoopSurface();
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace surfmap
