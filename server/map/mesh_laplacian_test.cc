#include "server/map/mesh_laplacian.h"

#include <algorithm>
#include <cmath>

#include <gtest/gtest.h>
#include "server/map/testing/flat_grid_levels.h"

namespace surfmap {
namespace {

TEST(GraphLaplacianTest, CotangentWeightsOfARegularGrid) {
  const SurfaceLevel level = testing::MakeFlatGrid(2, 2, 1.0);
  const GraphLaplacian g = BuildGraphLaplacian(level, LaplacianWeights::kCotangent);
  // An edge along the grid has two 45-degree corners opposite it: (cot 45 +
  // cot 45) / 2 = 1; a diagonal has two right corners: 0 (plus the lift).
  const int centre = 4;  // (1,1) of the 3 x 3 vertices
  for (int e = g.offsets[centre]; e < g.offsets[centre + 1]; ++e) {
    const int u = g.columns[e];
    const bool diagonal = u == 0 || u == 8;
    EXPECT_NEAR(g.weights[e], diagonal ? 0.0 : 1.0, 1e-9) << "edge to " << u;
  }
}

TEST(GraphLaplacianTest, ASliverCannotOutweighTheMesh) {
  const SurfaceLevel level = testing::MakeFlatGridWithSliver(20, 10);
  for (LaplacianWeights kind : {LaplacianWeights::kCotangent, LaplacianWeights::kCotangentClamped}) {
    const GraphLaplacian g = BuildGraphLaplacian(level, kind);
    double largest = 0.0;
    for (double w : g.weights) largest = std::max(largest, std::abs(w));
    // Each edge has two corners opposite it, each cot capped at cot(1 degree) = 57.3.
    EXPECT_LE(largest, 57.3 + 1e-6);
    EXPECT_GT(largest, 20.0);  // the sliver's edges still weigh much more than the grid's 1
  }
}

}  // namespace
}  // namespace surfmap
