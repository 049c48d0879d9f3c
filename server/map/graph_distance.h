// Distances across a surface, measured along the edges of a mesh level (a
// graph approximation of geodesic distance: never shorter than the geodesic,
// at most ~8% longer on a regular triangulation).
#pragma once

#include <span>
#include <vector>

#include "server/mesh/loop_surface.h"

namespace surfmap {

struct NearestSource {
  std::vector<double> distance_mm;  // per vertex; +inf where no source is reachable
  std::vector<int> source;          // per vertex: index into `sources` of the nearest one, -1 if none
};

// Multi-source Dijkstra over `level.neighbors` with edge lengths between
// `level.limit_positions`. Sources out of range are ignored (callers validate).
// Ties between equally near sources go to the lower source index, so the
// result is deterministic.
NearestSource NearestSourceDistance(const SurfaceLevel& level, std::span<const int> sources);

}  // namespace surfmap
