#include "server/haptics/surface_locator.h"

#include <limits>
#include <random>

#include <gtest/gtest.h>
#include "server/haptics/test_meshes.h"

namespace surfmap::haptics {
namespace {

double BruteForce(const SurfaceLocator& unused, const TextureMap& m, const Eigen::Vector3d& q) {
  double best = std::numeric_limits<double>::infinity();
  for (const auto& t : m.triangles) {
    best = std::min(best, ClosestPointOnTriangle(q, m.positions[t[0]], m.positions[t[1]], m.positions[t[2]])
                              .squared_distance);
  }
  return best;
}

// The grid answer must be exact: the same distance as a brute-force search,
// for queries on, near and far from the surface, with and without hints.
TEST(SurfaceLocatorTest, MatchesBruteForceEverywhere) {
  const TextureMap sphere = testing::Sphere(20.0, 24, 48);
  const SurfaceLocator locator(sphere.positions, sphere.triangles);
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::uniform_int_distribution<int> tri(0, static_cast<int>(sphere.triangles.size()) - 1);
  for (int i = 0; i < 2000; ++i) {
    Eigen::Vector3d dir(u(rng), u(rng), u(rng));
    if (dir.norm() < 1e-3) continue;
    // Radii from the centre (inside) to 3x the radius (far outside the grid).
    const double radius = 60.0 * (u(rng) + 1.0) / 2.0;
    const Eigen::Vector3d q = dir.normalized() * radius;
    const int hint = i % 3 == 0 ? -1 : tri(rng);  // random (mostly wrong) hints must not change the answer
    const TriangleHit hit = locator.Closest(q, hint);
    ASSERT_GE(hit.triangle, 0);
    // 1e-9 mm^2: rounding only (the same triangle formula on the same data).
    EXPECT_NEAR(hit.squared_distance, BruteForce(locator, sphere, q), 1e-9) << "query " << q.transpose();
  }
}

// A probe sliding along the surface with the previous answer as hint tests
// only a few triangles per query: the reason for the cache.
TEST(SurfaceLocatorTest, CoherentQueriesTestFewTriangles) {
  const TextureMap sphere = testing::Sphere(20.0, 48, 96);  // ~9k triangles
  const SurfaceLocator locator(sphere.positions, sphere.triangles);
  int hint = -1;
  long total = 0;
  const int steps = 2000;
  for (int i = 0; i < steps; ++i) {
    const double ph = 0.001 * i;  // 0.02 mm steps along the equator
    const Eigen::Vector3d q(20.0 * std::cos(ph), 20.0 * std::sin(ph), 0.3);
    const TriangleHit hit = locator.Closest(q, hint);
    hint = hit.triangle;
    total += SurfaceLocator::LastTrianglesTested();
  }
  // A cell holds ~10 triangles here and the query sits near a cell corner at
  // worst: 8 cells. 60 on average is far below a brute force (9216).
  EXPECT_LT(static_cast<double>(total) / steps, 60.0);
}

TEST(SurfaceLocatorTest, EmptyMeshFindsNothing) {
  const SurfaceLocator locator({}, {});
  EXPECT_EQ(locator.Closest(Eigen::Vector3d::Zero(), 3).triangle, -1);
}

}  // namespace
}  // namespace surfmap::haptics
