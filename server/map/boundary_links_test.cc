#include "server/map/boundary_links.h"

#include <gtest/gtest.h>
#include "server/map/testing/boundary_crossings.h"

namespace surfmap {
namespace {

using testing::Crossing;
using testing::DragData;

// Two drags across the boundary x = 0, 10 mm apart.
const std::vector<ChangeMark> kTwo = {Crossing(0.0, 0), Crossing(10.0, 1)};

TEST(BoundaryLinks, NeighbouringCrossingsOfAStraightBoundaryAreLinkedOnTheirOwnSides) {
  int links = 0;
  const std::vector<LabelledPoint> points =
      BoundaryLinkPoints(kTwo, DragData(kTwo), {}, &links);
  EXPECT_EQ(links, 1);
  ASSERT_FALSE(points.empty());
  const BoundaryLinkOptions o;
  for (const LabelledPoint& p : points) {
    // Every link point is seed_offset_mm on its own region's side (1e-9: rounding).
    EXPECT_NEAR(std::abs(p.point.x()), o.seed_offset_mm, 1e-9);
    EXPECT_EQ(p.label, p.point.x() < 0.0 ? 0 : 1);
    EXPECT_GE(p.point.y(), -1e-9);
    EXPECT_LE(p.point.y(), 10.0 + 1e-9);
  }
}

TEST(BoundaryLinks, CrossingsFartherApartThanTheLongestLinkAreNotLinked) {
  const BoundaryLinkOptions o;
  int links = 0;
  const std::vector<ChangeMark> marks = {Crossing(0.0, 0), Crossing(o.max_length_mm + 1.0, 1)};
  BoundaryLinkPoints(marks, DragData(marks), o, &links);
  EXPECT_EQ(links, 0);
}

TEST(BoundaryLinks, DataOfTheOtherSideInTheCorridorVetoesTheLink) {
  std::vector<LabelledPoint> data = DragData(kTwo);
  data.push_back({{-0.8, 5.0, 0.0}, 1});  // region 1 found 0.8 mm on region 0's side
  int links = 0;
  EXPECT_TRUE(BoundaryLinkPoints(kTwo, data, {}, &links).empty());
  EXPECT_EQ(links, 0);
}

TEST(BoundaryLinks, DragsFarFromPerpendicularToTheChordAreNotLinked) {
  // 45 degrees off perpendicular: beyond the 30 degrees allowed.
  const std::vector<ChangeMark> marks = {Crossing(0.0, 0, 45.0), Crossing(10.0, 1, 45.0)};
  int links = 0;
  BoundaryLinkPoints(marks, DragData(marks), {}, &links);
  EXPECT_EQ(links, 0);
}

TEST(BoundaryLinks, CrossingsOfOneDragOrOfDifferentRegionsAreNotLinked) {
  int links = 0;
  const std::vector<ChangeMark> one_drag = {Crossing(0.0, 3), Crossing(10.0, 3)};
  BoundaryLinkPoints(one_drag, DragData(one_drag), {}, &links);
  EXPECT_EQ(links, 0);
  ChangeMark other = Crossing(10.0, 1);
  other.after = 2;
  BoundaryLinkPoints({Crossing(0.0, 0), other}, DragData({Crossing(0.0, 0)}), {}, &links);
  EXPECT_EQ(links, 0);
}

}  // namespace
}  // namespace surfmap
