#include "server/estimate/path_pairing.h"

#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>

namespace surfmap {
namespace {

DragSample At(double t, double x, double y, DragPhase phase) {
  DragSample s;
  s.t = t;
  s.position = Eigen::Vector3d(x, y, 0.0);
  s.force = Eigen::Vector3d(0.0, 0.0, 5.0);
  s.phase = phase;
  return s;
}

// Forward along x at 0, 1, ..., 10 mm; reverse at uneven positions.
TEST(PathPairingTest, ProjectsReverseSamplesOntoTheForwardPath) {
  std::vector<DragSample> forward, reverse;
  for (int i = 0; i <= 10; ++i) forward.push_back(At(0.1 * i, i, 0.0, DragPhase::kForward));
  const std::vector<double> xs = {10.0, 9.7, 8.2, 8.1, 6.0, 3.3, 3.2, 1.05, 0.0};
  for (std::size_t j = 0; j < xs.size(); ++j) {
    reverse.push_back(At(2.0 + 0.1 * j, xs[j], 0.2, DragPhase::kReverse));
  }
  absl::StatusOr<PathPairing> pairing = PairPasses(forward, reverse);
  ASSERT_TRUE(pairing.ok()) << pairing.status();
  EXPECT_NEAR(pairing->path_length_mm, 10.0, 1e-12);
  for (int i = 0; i <= 10; ++i) EXPECT_NEAR(pairing->forward_s[i], i, 1e-12);
  for (std::size_t j = 0; j < xs.size(); ++j) EXPECT_NEAR(pairing->reverse_s[j], xs[j], 1e-12) << j;
  EXPECT_NEAR(pairing->max_offset_mm, 0.2, 1e-12);
  EXPECT_NEAR(pairing->covered_from_mm, 0.0, 1e-12);
  EXPECT_NEAR(pairing->covered_to_mm, 10.0, 1e-12);
}

// A quarter circle of radius 10 mm: arc length is r * angle along the curve.
TEST(PathPairingTest, FollowsACurvedPath) {
  std::vector<DragSample> forward, reverse;
  const int n = 400;
  const double r = 10.0, quarter = M_PI / 2;
  for (int i = 0; i <= n; ++i) {
    const double a = quarter * i / n;
    forward.push_back(At(0.01 * i, r * std::cos(a), r * std::sin(a), DragPhase::kForward));
  }
  for (int j = 0; j <= 37; ++j) {
    const double a = quarter * (1.0 - j / 37.0);
    reverse.push_back(At(10.0 + 0.01 * j, r * std::cos(a), r * std::sin(a), DragPhase::kReverse));
  }
  absl::StatusOr<PathPairing> pairing = PairPasses(forward, reverse);
  ASSERT_TRUE(pairing.ok()) << pairing.status();
  // The chord polyline and its +-2 sample smoothing pull inside the arc by ~3e-4 mm.
  const double arc = r * quarter;
  EXPECT_NEAR(pairing->path_length_mm, arc, 1e-3);
  for (int j = 0; j <= 37; ++j) {
    EXPECT_NEAR(pairing->reverse_s[j], arc * (1.0 - j / 37.0), 1e-3) << j;
  }
}

TEST(PathPairingTest, RejectsAReversePassThatDoesNotRetrace) {
  std::vector<DragSample> forward, reverse;
  for (int i = 0; i <= 200; ++i) forward.push_back(At(0.01 * i, 0.1 * i, 0.0, DragPhase::kForward));
  // 20 mm path: limit max(0.5, 5% of 20) = 1 mm. A parallel pass 1.5 mm away.
  for (int j = 0; j <= 200; ++j) {
    reverse.push_back(At(3.0 + 0.01 * j, 20.0 - 0.1 * j, 1.5, DragPhase::kReverse));
  }
  absl::StatusOr<PathPairing> pairing = PairPasses(forward, reverse);
  ASSERT_FALSE(pairing.ok());
  EXPECT_NE(std::string(pairing.status().message())
                .find("reverse pass does not retrace the forward path: reverse sample"),
            std::string::npos)
      << pairing.status();
  EXPECT_NE(std::string(pairing.status().message()).find("1.500 mm from the forward path (limit 1.000 mm"),
            std::string::npos)
      << pairing.status();
}

TEST(PathPairingTest, RejectsAReversePassGoingTheSameWay) {
  std::vector<DragSample> forward, reverse;
  for (int i = 0; i <= 100; ++i) forward.push_back(At(0.01 * i, 0.1 * i, 0.0, DragPhase::kForward));
  for (int j = 0; j <= 100; ++j) reverse.push_back(At(2.0 + 0.01 * j, 0.1 * j, 0.0, DragPhase::kReverse));
  EXPECT_FALSE(PairPasses(forward, reverse).ok());
}

TEST(PathPairingTest, RejectsAShortReversePass) {
  std::vector<DragSample> forward, reverse;
  for (int i = 0; i <= 100; ++i) forward.push_back(At(0.01 * i, 0.1 * i, 0.0, DragPhase::kForward));
  for (int j = 0; j <= 40; ++j) reverse.push_back(At(2.0 + 0.01 * j, 10.0 - 0.1 * j, 0.0, DragPhase::kReverse));
  absl::StatusOr<PathPairing> pairing = PairPasses(forward, reverse);
  ASSERT_FALSE(pairing.ok());
  EXPECT_NE(std::string(pairing.status().message())
                .find("reverse pass covers only 4.000 of the 10.000 mm forward path (40%, need 50%)"),
            std::string::npos)
      << pairing.status();
}

TEST(PathPairingTest, RejectsAForwardPassThatDoesNotMove) {
  std::vector<DragSample> forward, reverse;
  for (int i = 0; i < 5; ++i) forward.push_back(At(0.01 * i, 1.0, 1.0, DragPhase::kForward));
  reverse.push_back(At(1.0, 1.0, 1.0, DragPhase::kReverse));
  absl::StatusOr<PathPairing> pairing = PairPasses(forward, reverse);
  ASSERT_FALSE(pairing.ok());
  EXPECT_NE(std::string(pairing.status().message()).find("does not move"), std::string::npos);
}

TEST(MonotoneBracketTest, InterpolatesAndClamps) {
  const std::vector<double> keys = {0.0, 1.0, 1.0, 3.0};
  MonotoneBracket bracket(4);
  const auto key = [&](int i) { return keys[i]; };
  int i;
  double w;
  bracket.Locate(-1.0, key, &i, &w);
  EXPECT_EQ(i, 0);
  EXPECT_EQ(w, 0.0);
  bracket.Locate(0.25, key, &i, &w);
  EXPECT_EQ(i, 0);
  EXPECT_DOUBLE_EQ(w, 0.25);
  bracket.Locate(2.5, key, &i, &w);
  EXPECT_EQ(i, 2);
  EXPECT_DOUBLE_EQ(w, 0.75);
  bracket.Locate(9.0, key, &i, &w);
  EXPECT_EQ(i, 2);
  EXPECT_EQ(w, 1.0);
}

}  // namespace
}  // namespace surfmap
