// Where the boundary-seeking plan sends the next drag, and which way
// (PlanMode::kBoundary). A drag of length L measures the surface along its
// path and pins any boundary it crosses; its effect reaches about L/2 around
// its centre. So the gain of a drag centred at vertex c is the map's
// removable variance summed over the surface within L/2 of c:
//
//   gain(c) = sum over vertices v with |x_v - x_c| <= L/2 of
//             area(v) * (boundary_variance(v) + far_variance(v))
//
// (region_map.h; mu^2 mm^2: the squared error mass the drag can remove).
// Near a boundary no drag has pinned, the band where the map may be wrong
// is as wide as the gap between the data on either side, so the sum prefers
// unpinned stretches of boundary over the neighbourhood of a crossing that
// is already known; far from data it prefers the middle of the gap. Vertices
// within L/2 of a drag already issued count as covered (several rigs get
// different places). The drag crosses the boundary when the boundary term
// is most of the gain (across the boundary at the ball's most uncertain
// boundary vertex); otherwise it runs perpendicular to the direction of the
// nearest data, covering new ground.
#pragma once

#include <span>
#include <vector>

#include <Eigen/Core>
#include "server/map/region_map.h"

namespace surfmap {

struct BoundarySelection {
  int vertex = -1;           // of the map's level; -1 when no candidate has any gain
  double gain = 0.0;         // mu^2 mm^2
  double boundary_share = 0.0;  // of the gain
  Eigen::Vector3d direction = Eigen::Vector3d::Zero();  // unit tangent
};

class BoundarySelector {
 public:
  // `level` is the map's level (the selector keeps its vertex areas and a
  // spatial grid of its vertices); `reach_mm` = half the drag length.
  BoundarySelector(const SurfaceLevel& level, double reach_mm);

  // The candidate with the largest gain among those with candidate[v] != 0
  // (one entry per vertex of the level; vertices beyond its size are not
  // candidates). Ties go to the lower vertex. `covered` are the centres of
  // drags issued and not yet measured.
  BoundarySelection Select(const RegionMap& map, std::span<const char> candidate,
                           const std::vector<Eigen::Vector3d>& covered) const;

  // The direction for a drag at v given the map alone (initial sites that are
  // issued after some data came in): across the boundary when v is within
  // reach of one (a second region with a boundary variance there), else zero.
  Eigen::Vector3d CrossingNear(const RegionMap& map, int v) const;

  double reach_mm() const { return reach_mm_; }

 private:
  template <typename Fn>
  void ForEachWithin(const Eigen::Vector3d& centre, double radius, const Fn& fn) const;

  const SurfaceLevel* level_;
  double reach_mm_;
  std::vector<double> area_;  // a third of the area of the triangles around each vertex
  Eigen::Vector3d lo_;
  Eigen::Vector3i dims_;
  std::vector<std::vector<int>> grid_;  // cells of reach_mm
};

}  // namespace surfmap
