#include "server/geometry/closest_point.h"

#include <algorithm>
#include <limits>
#include <random>

#include "gtest/gtest.h"

namespace surfmap {
namespace {

const Eigen::Vector3d kA(0, 0, 0), kB(4, 0, 0), kC(0, 3, 0);

TEST(ClosestPointOnTriangleTest, AboveTheFaceProjectsStraightDown) {
  const ClosestTriangle hit = ClosestPointOnTriangle({1, 1, 2}, kA, kB, kC);
  EXPECT_TRUE(hit.position.isApprox(Eigen::Vector3d(1, 1, 0)));
  EXPECT_DOUBLE_EQ(hit.squared_distance, 4.0);
  EXPECT_NEAR(hit.barycentric.sum(), 1.0, 1e-15);
  EXPECT_TRUE((hit.barycentric.x() * kA + hit.barycentric.y() * kB + hit.barycentric.z() * kC).isApprox(hit.position));
}

TEST(ClosestPointOnTriangleTest, VertexAndEdgeRegionsGetExactZeros) {
  const ClosestTriangle corner = ClosestPointOnTriangle({-1, -1, 0}, kA, kB, kC);
  EXPECT_EQ(corner.barycentric, Eigen::Vector3d(1, 0, 0));
  const ClosestTriangle edge = ClosestPointOnTriangle({2, -5, 1}, kA, kB, kC);  // below edge AB
  EXPECT_EQ(edge.barycentric.z(), 0.0);
  EXPECT_TRUE(edge.position.isApprox(Eigen::Vector3d(2, 0, 0)));
  EXPECT_DOUBLE_EQ(edge.squared_distance, 26.0);
}

TEST(ClosestPointOnTriangleTest, NoPointOfTheTriangleIsCloser) {
  // Against a dense barycentric grid: the answer is never farther than the
  // best grid point (up to the grid's own spacing, 1/200 of an edge).
  std::mt19937 random(5);
  std::uniform_real_distribution<double> coordinate(-6.0, 6.0);
  for (int trial = 0; trial < 200; ++trial) {
    const Eigen::Vector3d p(coordinate(random), coordinate(random), coordinate(random));
    const ClosestTriangle hit = ClosestPointOnTriangle(p, kA, kB, kC);
    double best = std::numeric_limits<double>::infinity();
    constexpr int kSteps = 200;
    for (int i = 0; i <= kSteps; ++i) {
      for (int j = 0; i + j <= kSteps; ++j) {
        const double u = static_cast<double>(i) / kSteps, v = static_cast<double>(j) / kSteps;
        best = std::min(best, (p - ((1 - u - v) * kA + u * kB + v * kC)).squaredNorm());
      }
    }
    EXPECT_LE(hit.squared_distance, best + 1e-12) << "trial " << trial;
    EXPECT_GE(hit.barycentric.minCoeff(), 0.0);
  }
}

}  // namespace
}  // namespace surfmap
