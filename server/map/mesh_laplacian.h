// Edge weights of the graph Laplacian of a mesh level, used by the harmonic
// interpolation of the map.
#pragma once

#include <vector>

#include "server/mesh/loop_surface.h"

namespace surfmap {

enum class LaplacianWeights {
  // Cotangent weights (w_ij = (cot a + cot b) / 2) from the limit positions:
  // the stiffness matrix of linear finite elements on the surface, an
  // intrinsic operator, so interpolation follows the surface and reproduces
  // linear fields exactly on any flat mesh. Edges opposite obtuse angles get
  // negative weights; the matrix stays positive semi-definite, but
  // interpolated values may overshoot the samples slightly there (the map
  // clamps every field to the range of its samples).
  kCotangent,
  // Cotangent weights with negative ones raised to 0: a true maximum
  // principle, at the price of linear precision on meshes with obtuse angles.
  kCotangentClamped,
  // Every edge weighs 1 (graph Laplacian); ignores geometry.
  kUniform,
};

// Symmetric weights in compressed rows aligned with `level.neighbors`: the
// weight of the edge from v to level.neighbors[v][k] is
// weights[offsets[v] + k]. For the cotangent kinds every weight is raised by
// 1e-10 times the mean |weight|, so that an edge whose cotangents cancel
// (e.g. the diagonals of a regular grid) still links its ends and a vertex
// whose triangles are all degenerate does not make the system singular.
struct GraphLaplacian {
  std::vector<int> offsets;  // size nv + 1
  std::vector<int> columns;  // neighbour vertex of each entry
  std::vector<double> weights;
};

GraphLaplacian BuildGraphLaplacian(const SurfaceLevel& level, LaplacianWeights kind);

}  // namespace surfmap
