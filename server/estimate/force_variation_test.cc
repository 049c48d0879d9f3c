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
  const std::vector<Eigen::Vector3d> averaged = SeriesNormals(f, SeriesOptions{});
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
  const std::vector<Eigen::Vector3d> averaged = SeriesNormals(f, SeriesOptions{});
  for (int i = 0; i < f.n_pairs; ++i) {
    EXPECT_LT(NormalAngleDeg(averaged[i], turning(f.pair_s_mm[i])), 0.05) << "pair " << i;
  }
}

// Over a sharp edge (a CAD part's facets) the two faces' normals are not
// blended: only normals within max_turn_deg of a pair's own join its average.
TEST(SeriesNormalsTest, TheFacesOfASharpEdgeAreNotBlended) {
  const auto edge = [](double s) { return s < 4.0 ? Eigen::Vector3d::UnitZ() : Eigen::Vector3d::UnitX(); };
  const FrictionFit f = PairsWithNormals(8.0, edge, 0.5, 3);
  const std::vector<Eigen::Vector3d> averaged = SeriesNormals(f, SeriesOptions{});
  for (int i = 0; i < f.n_pairs; ++i) {
    EXPECT_LT(NormalAngleDeg(averaged[i], edge(f.pair_s_mm[i])), 2.0) << "pair " << i << " at " << f.pair_s_mm[i];
  }
}

TEST(SeriesNormalsTest, HalfwidthZeroIsEachPairsOwnNormal) {
  const auto up = [](double) { return Eigen::Vector3d::UnitZ(); };
  const FrictionFit f = PairsWithNormals(5.0, up, 2.0, 11);
  SeriesOptions own;
  own.halfwidth_mm = 0.0;
  const std::vector<Eigen::Vector3d> normals = SeriesNormals(f, own);
  ASSERT_EQ(normals.size(), f.pair_normal.size());
  for (int i = 0; i < f.n_pairs; ++i) EXPECT_EQ(normals[i], f.pair_normal[i]);
}

// Samples about every 0.1 mm whose spacing wanders by 4 % (the rig's speed):
// a fixed grid drifts across them, and where it falls halfway between two it
// takes one twice and skips the next; following the samples takes each once.
TEST(ReadAtStepTest, FollowingTheSamplesTakesEachOnceWhereAGridDoubles) {
  std::vector<double> pos, val;
  double s = 0.05;  // half a step off the grid
  for (int i = 0; i < 200; ++i) {
    pos.push_back(s);
    val.push_back(i);  // each sample's value is its index
    s += 0.1 * (1.0 + 0.04 * std::sin(i / 25.0));
  }
  const std::vector<double> followed = ReadAtStep(pos, val, 0.0, pos.back(), 0.1, true);
  ASSERT_EQ(followed.size(), pos.size());
  for (int i = 0; i < static_cast<int>(followed.size()); ++i) EXPECT_EQ(followed[i], i);
  const std::vector<double> grid = ReadAtStep(pos, val, 0.0, pos.back(), 0.1, false);
  int twice = 0, skipped = 0;
  for (std::size_t i = 1; i < grid.size(); ++i) {
    twice += grid[i] == grid[i - 1];
    skipped += grid[i] > grid[i - 1] + 1;
  }
  EXPECT_GT(twice, 0);
  EXPECT_GT(skipped, 0);
}

// A probe sampling five times per step: every fifth sample, none twice.
TEST(ReadAtStepTest, AFasterProbeIsReadEveryNthSample) {
  std::vector<double> pos, val;
  for (int i = 0; i <= 500; ++i) {
    pos.push_back(0.02 * i);
    val.push_back(i);
  }
  const std::vector<double> followed = ReadAtStep(pos, val, 1.0, 9.0, 0.1, true);
  ASSERT_EQ(followed.size(), 81u);
  for (std::size_t i = 0; i < followed.size(); ++i) EXPECT_EQ(followed[i], 50 + 5 * static_cast<int>(i));
}

// A step that is not positive, a window that runs backwards or one past the
// series' limit reads nothing, in either mode, and allocates nothing.
TEST(ReadAtStepTest, AStepOrWindowItCannotReadGivesNothing) {
  const std::vector<double> pos = {0.0, 0.1, 0.2}, val = {1.0, 2.0, 3.0};
  for (bool follow : {true, false}) {
    EXPECT_TRUE(ReadAtStep(pos, val, 0.0, 0.2, 0.0, follow).empty());
    EXPECT_TRUE(ReadAtStep(pos, val, 0.0, 0.2, -0.1, follow).empty());
    EXPECT_TRUE(ReadAtStep(pos, val, 0.0, 0.2, std::nan(""), follow).empty());
    EXPECT_TRUE(ReadAtStep(pos, val, 0.2, 0.0, 0.1, follow).empty());
    EXPECT_TRUE(ReadAtStep(pos, val, 0.0, 1e9, 1e-6, follow).empty());
    EXPECT_TRUE(ReadAtStep({}, {}, 0.0, 0.2, 0.1, follow).empty());
    EXPECT_EQ(ReadAtStep(pos, val, 0.0, 0.2, 0.1, follow).size(), 3u);
  }
}

TEST(SeriesNormalsTest, BadOptionsAreNamed) {
  std::string why;
  SeriesOptions o;
  o.halfwidth_mm = -0.1;
  EXPECT_FALSE(o.IsValid(&why));
  EXPECT_EQ(why, "series normal halfwidth_mm must be in 0..10");
  o = SeriesOptions{};
  o.max_turn_deg = 0.0;
  EXPECT_FALSE(o.IsValid(&why));
  EXPECT_EQ(why, "series normal max_turn_deg must be in (0, 90]");
  EXPECT_TRUE(SeriesOptions{}.IsValid(&why));
}

}  // namespace
}  // namespace surfmap
