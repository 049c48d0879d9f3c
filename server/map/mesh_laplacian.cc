#include "server/map/mesh_laplacian.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>

namespace surfmap {
namespace {

// Position of u in v's sorted neighbour row, or -1.
int EntryOf(const GraphLaplacian& g, int v, int u) {
  auto begin = g.columns.begin() + g.offsets[v];
  auto end = g.columns.begin() + g.offsets[v + 1];
  auto it = std::lower_bound(begin, end, u);
  if (it == end || *it != u) return -1;
  return static_cast<int>(it - g.columns.begin());
}

void AddSymmetric(GraphLaplacian& g, int a, int b, double w) {
  const int ab = EntryOf(g, a, b), ba = EntryOf(g, b, a);
  if (ab < 0 || ba < 0) return;  // a triangle edge missing from the adjacency: ignore it
  g.weights[ab] += w;
  g.weights[ba] += w;
}

// A corner's cotangent is kept within +-cot(1 degree). A sliver (a scan's
// fine level moved onto its bumps, dense_surface.h, folds a few triangles
// flat) has cotangents up to ~1e299: one such edge outweighs the rest of
// the mesh, and the random walker, whose seed stiffness scales with the mean
// weight, solves a system so badly conditioned that its fields are noise
// (scanned_mesh_test's pebble: 920 of 68,610 vertices, 5-15 mm from any
// boundary, took the region of the other side). Every corner above 1 degree
// is unchanged: the bundled scenes' maps are the same, point for point
// (docs/method.md).
constexpr double kMaxCotangent = 57.28996163075943;  // cot(1 degree)

}  // namespace

GraphLaplacian BuildGraphLaplacian(const SurfaceLevel& level, LaplacianWeights kind) {
  const int nv = static_cast<int>(level.limit_positions.size());
  GraphLaplacian g;
  g.offsets.assign(nv + 1, 0);
  for (int v = 0; v < nv; ++v) {
    const int row = v < static_cast<int>(level.neighbors.size()) ? static_cast<int>(level.neighbors[v].size()) : 0;
    g.offsets[v + 1] = g.offsets[v] + row;
  }
  g.columns.reserve(g.offsets[nv]);
  for (int v = 0; v < nv; ++v) {
    if (v < static_cast<int>(level.neighbors.size())) {
      g.columns.insert(g.columns.end(), level.neighbors[v].begin(), level.neighbors[v].end());
    }
  }
  if (kind == LaplacianWeights::kUniform) {
    g.weights.assign(g.columns.size(), 1.0);
    return g;
  }
  g.weights.assign(g.columns.size(), 0.0);
  const auto& p = level.limit_positions;
  for (const auto& t : level.triangles) {
    if (t[0] < 0 || t[1] < 0 || t[2] < 0 || t[0] >= nv || t[1] >= nv || t[2] >= nv) continue;
    for (int i = 0; i < 3; ++i) {
      const int a = t[i], b = t[(i + 1) % 3], c = t[(i + 2) % 3];
      const Eigen::Vector3d ab = p[b] - p[a], ac = p[c] - p[a];
      const double area2 = ab.cross(ac).norm();
      if (!(area2 > 0.0)) continue;  // degenerate corner: contributes nothing
      AddSymmetric(g, b, c, 0.5 * std::clamp(ab.dot(ac) / area2, -kMaxCotangent, kMaxCotangent));
    }
  }
  if (kind == LaplacianWeights::kCotangentClamped) {
    for (double& w : g.weights) w = std::max(w, 0.0);
  }
  double sum = 0.0;
  for (double w : g.weights) sum += std::abs(w);
  const double lift = 1e-10 * (g.weights.empty() || sum == 0.0 ? 1.0 : sum / g.weights.size());
  for (double& w : g.weights) w += lift;
  return g;
}

}  // namespace surfmap
