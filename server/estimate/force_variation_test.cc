#include "server/estimate/force_variation.h"

#include <cmath>
#include <cstdint>
#include <functional>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

namespace surfmap {
namespace {

double NormalAngleDeg(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::atan2(a.cross(b).norm(), a.dot(b)) * 180.0 / std::numbers::pi;
}

// Pairs every 0.1 mm over `length_mm` with normal(s) tilted by seeded noise
// of `tilt_deg` per axis.
FrictionFit PairsWithNormals(double length_mm, const std::function<Eigen::Vector3d(double)>& normal,
                             double tilt_deg, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> gauss(0.0, tilt_deg * std::numbers::pi / 180.0);
  FrictionFit f;
  for (double s = 0.0; s <= length_mm + 1e-9; s += 0.1) {
    const Eigen::Vector3d n = normal(s);
    f.pair_s_mm.push_back(s);
    f.pair_normal.push_back((n + Eigen::Vector3d(gauss(rng), gauss(rng), gauss(rng))).normalized());
    f.pair_mu.push_back(0.3);
  }
  f.n_pairs = static_cast<int>(f.pair_s_mm.size());
  return f;
}

// The texture's tilt of the bisector changes every pair; the average over
// +-0.5 mm (11 pairs) cuts it by about sqrt(11).
TEST(SeriesNormalsTest, AveragingRemovesTheTiltThatChangesEveryPair) {
  const auto up = [](double) { return Eigen::Vector3d::UnitZ(); };
  const FrictionFit f = PairsWithNormals(16.0, up, 1.5, 7);
  const std::vector<Eigen::Vector3d> averaged = SeriesNormals(f, SeriesNormalOptions{});
  ASSERT_EQ(averaged.size(), f.pair_normal.size());
  double own2 = 0.0, averaged2 = 0.0;
  for (int i = 10; i + 10 < f.n_pairs; ++i) {  // away from the narrowed ends
    own2 += std::pow(NormalAngleDeg(f.pair_normal[i], Eigen::Vector3d::UnitZ()), 2);
    averaged2 += std::pow(NormalAngleDeg(averaged[i], Eigen::Vector3d::UnitZ()), 2);
  }
  EXPECT_LT(averaged2, own2 / 6.0);
}

// A normal that turns steadily (a 5 mm radius) is not biased by the average:
// the window is symmetric, narrowed at the ends rather than made one-sided.
TEST(SeriesNormalsTest, ASteadilyTurningNormalIsNotBiasedEvenAtTheEnds) {
  const auto turning = [](double s) { return Eigen::Vector3d(std::sin(s / 5.0), 0.0, std::cos(s / 5.0)); };
  const FrictionFit f = PairsWithNormals(8.0, turning, 0.0, 1);
  const std::vector<Eigen::Vector3d> averaged = SeriesNormals(f, SeriesNormalOptions{});
  for (int i = 0; i < f.n_pairs; ++i) {
    EXPECT_LT(NormalAngleDeg(averaged[i], turning(f.pair_s_mm[i])), 0.05) << "pair " << i;
  }
}

// Over a sharp edge (a CAD part's facets) the two faces' normals are not
// blended: only normals within max_turn_deg of a pair's own join its average.
TEST(SeriesNormalsTest, TheFacesOfASharpEdgeAreNotBlended) {
  const auto edge = [](double s) { return s < 4.0 ? Eigen::Vector3d::UnitZ() : Eigen::Vector3d::UnitX(); };
  const FrictionFit f = PairsWithNormals(8.0, edge, 0.5, 3);
  const std::vector<Eigen::Vector3d> averaged = SeriesNormals(f, SeriesNormalOptions{});
  for (int i = 0; i < f.n_pairs; ++i) {
    EXPECT_LT(NormalAngleDeg(averaged[i], edge(f.pair_s_mm[i])), 2.0) << "pair " << i << " at " << f.pair_s_mm[i];
  }
}

TEST(SeriesNormalsTest, HalfwidthZeroIsEachPairsOwnNormal) {
  const auto up = [](double) { return Eigen::Vector3d::UnitZ(); };
  const FrictionFit f = PairsWithNormals(5.0, up, 2.0, 11);
  SeriesNormalOptions own;
  own.halfwidth_mm = 0.0;
  const std::vector<Eigen::Vector3d> normals = SeriesNormals(f, own);
  ASSERT_EQ(normals.size(), f.pair_normal.size());
  for (int i = 0; i < f.n_pairs; ++i) EXPECT_EQ(normals[i], f.pair_normal[i]);
}

TEST(SeriesNormalsTest, BadOptionsAreNamed) {
  std::string why;
  SeriesNormalOptions o;
  o.halfwidth_mm = -0.1;
  EXPECT_FALSE(o.IsValid(&why));
  EXPECT_EQ(why, "series normal halfwidth_mm must be in 0..10");
  o = SeriesNormalOptions{};
  o.max_turn_deg = 0.0;
  EXPECT_FALSE(o.IsValid(&why));
  EXPECT_EQ(why, "series normal max_turn_deg must be in (0, 90]");
  EXPECT_TRUE(SeriesNormalOptions{}.IsValid(&why));
}

}  // namespace
}  // namespace surfmap
