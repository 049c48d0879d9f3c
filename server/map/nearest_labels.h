// The two nearest labels at every vertex of a surface level: a geodesic
// Voronoi diagram of labelled data points (e.g. the points along the pieces
// of the drags, labelled by region) that also knows, at each vertex, the
// nearest data of a different label. The map draws its boundaries where the
// nearest label changes and interpolates inside triangles with both
// distances.
//
// Distances: every vertex keeps the data point it was reached from and its
// distance is the straight (chord) distance to that point, propagated over
// the level's edges in Dijkstra order (a vector distance transform). Within a
// drag's reach (~20 mm) the chord is the geodesic to within ~1 % even on a
// 15 mm tube, and unlike sums of edge lengths (up to ~8 % long, anisotropic)
// it puts the bisector between two drags where it belongs. Propagation along
// the edges keeps the regions connected through the surface: no shortcut
// across a handle's hole.
#pragma once

#include <array>
#include <span>
#include <vector>

#include <Eigen/Core>
#include "server/mesh/loop_surface.h"

namespace surfmap {

// A data point on (or very near) the surface and the level vertex it enters
// the graph at (callers seed the three corners of the triangle holding it).
struct LabelledSeed {
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  int vertex = -1;
  int label = -1;  // >= 0
};

struct NearestLabels {
  // Per vertex, up to two distinct labels, nearest first; label -1 and
  // distance +inf where fewer were reachable.
  std::vector<std::array<int, 2>> label;
  std::vector<std::array<double, 2>> distance_mm;
  std::vector<std::array<int, 2>> seed;  // index into the seeds, -1 where absent
};

// Seeds with a vertex out of range or a negative label are ignored. Ties go
// to the lower seed index, so the result is deterministic.
NearestLabels FindNearestLabels(const SurfaceLevel& level, std::span<const LabelledSeed> seeds);

}  // namespace surfmap
