#include "server/plan/boundary_tracing.h"

#include <gtest/gtest.h>

namespace surfmap {
namespace {

// Positions are sums of small integers: exact.
constexpr double kExact = 1e-12;

// A crossing at `at` by drag `drag` running along +x on the z = 0 plane,
// from region `before` into `after`; the boundary runs along z x x = +y.
ChangeMark Crossing(Eigen::Vector3d at, int drag, int before = 0, int after = 1) {
  ChangeMark m;
  m.position = at;
  m.direction = Eigen::Vector3d::UnitX();
  m.normal = Eigen::Vector3d::UnitZ();
  m.before = before;
  m.after = after;
  m.drag = drag;
  return m;
}

TEST(OpenTraceTargets, ALoneCrossingIsFollowedAStepEachWayAcrossTheBoundary) {
  const auto targets = OpenTraceTargets({Crossing({0, 0, 0}, 1)}, {});
  ASSERT_EQ(targets.size(), 2u);
  // step = 0.6 x 20 mm.
  EXPECT_NEAR((targets[0].point - Eigen::Vector3d(0, 12, 0)).norm(), 0.0, kExact);
  EXPECT_NEAR((targets[1].point - Eigen::Vector3d(0, -12, 0)).norm(), 0.0, kExact);
  for (const TraceTarget& t : targets) {
    EXPECT_NEAR((t.direction - Eigen::Vector3d::UnitX()).norm(), 0.0, kExact);
    EXPECT_EQ(t.mark, 0);
  }
}

TEST(OpenTraceTargets, ACrossingOfTheSameBoundaryWithinALinkClosesThatSideOnly) {
  const auto targets = OpenTraceTargets({Crossing({0, 0, 0}, 1), Crossing({1, 15, 0}, 2)}, {});
  // Mark 0's +y side and mark 1's -y side are closed by each other.
  ASSERT_EQ(targets.size(), 2u);
  EXPECT_EQ(targets[0].mark, 0);
  EXPECT_EQ(targets[0].side, -1);
  EXPECT_EQ(targets[1].mark, 1);
  EXPECT_EQ(targets[1].side, +1);
}

TEST(OpenTraceTargets, ABandsOtherEdgeAFarCrossingOrTheSameDragCloseNothing) {
  // The other edge of a band: the same two regions the other way round.
  EXPECT_EQ(OpenTraceTargets({Crossing({0, 0, 0}, 1), Crossing({10, 5, 0}, 2, 1, 0)}, {}).size(), 4u);
  // Beyond the link length (20 mm).
  EXPECT_EQ(OpenTraceTargets({Crossing({0, 0, 0}, 1), Crossing({0, 21, 0}, 2)}, {}).size(), 4u);
  // Another crossing of the same drag is not a second look at the boundary.
  EXPECT_EQ(OpenTraceTargets({Crossing({0, 0, 0}, 1), Crossing({0, 10, 0}, 1)}, {}).size(), 4u);
  // Another pair of regions is another boundary.
  EXPECT_EQ(OpenTraceTargets({Crossing({0, 0, 0}, 1), Crossing({0, 10, 0}, 2, 0, 2)}, {}).size(), 4u);
}

TEST(OpenTraceTargets, ADragAcrossATargetExploresItOneAlongTheBoundaryDoesNot) {
  const std::vector<ChangeMark> marks = {Crossing({0, 0, 0}, 1)};
  // Across the boundary at y = 12, its window reaching x = 0 within 1.5 mm.
  const DragSegment across{{-9.0, 12.0, 0.0}, {-1.0, 12.0, 0.0}};
  auto targets = OpenTraceTargets(marks, {across});
  ASSERT_EQ(targets.size(), 1u);
  EXPECT_EQ(targets[0].side, -1);
  // Through the target but along the boundary: it cannot see where it crosses.
  const DragSegment along{{0.0, 4.0, 0.0}, {0.0, 20.0, 0.0}};
  EXPECT_EQ(OpenTraceTargets(marks, {along}).size(), 2u);
  // Across, but its window ends 2 mm short of the target.
  const DragSegment short_of{{-10.0, 12.0, 0.0}, {-2.0, 12.0, 0.0}};
  EXPECT_EQ(OpenTraceTargets(marks, {short_of}).size(), 2u);
}

}  // namespace
}  // namespace surfmap
