#include "server/map/boundary_links.h"

#include <gtest/gtest.h>

namespace surfmap {
namespace {

// A straight boundary x = 0 on the plate z = 0: region 0 at x < 0, region 1
// at x > 0, crossed by drags running along +x.
ChangeMark Crossing(double y, int drag, const Eigen::Vector3d& direction = Eigen::Vector3d::UnitX()) {
  ChangeMark m;
  m.position = {0.0, y, 0.0};
  m.direction = direction.normalized();
  m.normal = Eigen::Vector3d::UnitZ();
  m.before = 0;
  m.after = 1;
  m.drag = drag;
  return m;
}

// The drags' own data either side of the boundary.
std::vector<LabelledPoint> DragData(const std::vector<double>& ys) {
  std::vector<LabelledPoint> data;
  for (double y : ys) {
    for (double x = -8.0; x <= 8.0; x += 1.0) {
      if (x != 0.0) data.push_back({{x, y, 0.0}, x < 0.0 ? 0 : 1});
    }
  }
  return data;
}

TEST(BoundaryLinks, NeighbouringCrossingsOfAStraightBoundaryAreLinkedOnTheirOwnSides) {
  int links = 0;
  const std::vector<LabelledPoint> points =
      BoundaryLinkPoints({Crossing(0.0, 0), Crossing(10.0, 1)}, DragData({0.0, 10.0}), {}, &links);
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
  BoundaryLinkPoints({Crossing(0.0, 0), Crossing(o.max_length_mm + 1.0, 1)}, DragData({0.0, o.max_length_mm + 1.0}), o,
                     &links);
  EXPECT_EQ(links, 0);
}

TEST(BoundaryLinks, DataOfTheOtherSideInTheCorridorVetoesTheLink) {
  std::vector<LabelledPoint> data = DragData({0.0, 10.0});
  data.push_back({{-0.8, 5.0, 0.0}, 1});  // region 1 found 0.8 mm on region 0's side
  int links = 0;
  EXPECT_TRUE(BoundaryLinkPoints({Crossing(0.0, 0), Crossing(10.0, 1)}, data, {}, &links).empty());
  EXPECT_EQ(links, 0);
}

TEST(BoundaryLinks, DragsFarFromPerpendicularToTheChordAreNotLinked) {
  // 45 degrees off perpendicular: beyond the 30 degrees allowed.
  const Eigen::Vector3d oblique(1.0, 1.0, 0.0);
  int links = 0;
  BoundaryLinkPoints({Crossing(0.0, 0, oblique), Crossing(10.0, 1, oblique)}, DragData({0.0, 10.0}), {}, &links);
  EXPECT_EQ(links, 0);
}

TEST(BoundaryLinks, CrossingsOfOneDragOrOfDifferentRegionsAreNotLinked) {
  int links = 0;
  BoundaryLinkPoints({Crossing(0.0, 3), Crossing(10.0, 3)}, DragData({0.0, 10.0}), {}, &links);
  EXPECT_EQ(links, 0);
  ChangeMark other = Crossing(10.0, 1);
  other.after = 2;
  BoundaryLinkPoints({Crossing(0.0, 0), other}, DragData({0.0}), {}, &links);
  EXPECT_EQ(links, 0);
}

}  // namespace
}  // namespace surfmap
