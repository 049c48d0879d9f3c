#include "server/plan/boundary_tracing.h"

#include <gtest/gtest.h>
#include "server/map/testing/map_pieces.h"

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

// ContinuationError on a plate: glass (0.13) and sandpaper (0.5) met by
// drags along +x. Window +/-8 mm sampled every mm, corridor 5 mm.
constexpr double kHalfWindow = 8.0, kCorridor = 5.0, kJump = 0.5 - 0.13;

// The error of the open target on side `side` of the crossing by `drag`.
double ErrorOfTarget(const RegionMap& map, int drag, int side) {
  const std::vector<ChangeMark>& marks = map.change_marks();
  for (const TraceTarget& t : OpenTraceTargets(marks, {})) {
    if (marks[t.mark].drag == drag && t.side == side) {
      return ContinuationError(t, marks[t.mark], map, kHalfWindow, kCorridor);
    }
  }
  ADD_FAILURE() << "no open target on side " << side << " of drag " << drag;
  return -1.0;
}

TEST(ContinuationError, NoneWhereTheMapAlreadyCarriesTheBoundaryOn) {
  // Glass left of x = 0, sandpaper right, crossed at y = -8 and y = 8.
  const SurfaceLevel level = testing::Plate();
  auto map = RegionMap::Create(level);
  ASSERT_TRUE(map.ok());
  std::vector<MapPiece> pieces = {testing::StraightPiece(0, {-20, -20, 0}, {-20, 20, 0}, 0.13),
                                  testing::StraightPiece(1, {20, -20, 0}, {20, 20, 0}, 0.5)};
  for (double y : {-8.0, 8.0}) {
    for (MapPiece& p : testing::CrossingDrag(y < 0 ? 2 : 3, {-8, y, 0}, {0, y, 0}, {8, y, 0}, 0.13, 0.5)) {
      pieces.push_back(p);
    }
  }
  ASSERT_TRUE(map->SetPieces(pieces).ok());
  // The -8 crossing's +y side is closed by the other crossing; its -y side
  // (y = -20) is open, and the map already has the boundary there.
  EXPECT_EQ(ErrorOfTarget(*map, 2, -1), 0.0);
}

TEST(ContinuationError, TheWholeFarSideWhereDataOfOneRegionPinchedANarrowBandOff) {
  // A sandpaper band x in [0, 6] crossed once at y = -15; glass drags along
  // y at x = -4 and x = 10 from y = -5 on pinch it off further up.
  const SurfaceLevel level = testing::Plate();
  auto map = RegionMap::Create(level);
  ASSERT_TRUE(map.ok());
  std::vector<MapPiece> pieces = {testing::StraightPiece(0, {-4, -5, 0}, {-4, 20, 0}, 0.13),
                                  testing::StraightPiece(1, {10, -5, 0}, {10, 20, 0}, 0.13)};
  MapPiece glass = testing::StraightPiece(2, {-8, -15, 0}, {0, -15, 0}, 0.13);
  glass.piece.ends_at_change = true;
  MapPiece band = testing::StraightPiece(2, {0, -15, 0}, {6, -15, 0}, 0.5, 8.0);
  band.piece.starts_at_change = band.piece.ends_at_change = true;
  MapPiece beyond = testing::StraightPiece(2, {6, -15, 0}, {10, -15, 0}, 0.13, 14.0);
  beyond.piece.starts_at_change = true;
  pieces.insert(pieces.end(), {glass, band, beyond});
  ASSERT_TRUE(map->SetPieces(pieces).ok());
  ASSERT_EQ(map->regions().size(), 2u);
  // At the target (0, -3) the map is glass across the whole window, so the
  // eight 1 mm samples beyond it, where the band would go on, are wrong.
  EXPECT_NEAR(ErrorOfTarget(*map, 2, +1), 8.0 * 2.0 * kCorridor * kJump * kJump, 1e-9);
}

}  // namespace
}  // namespace surfmap
