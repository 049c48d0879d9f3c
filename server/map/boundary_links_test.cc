#include "server/map/boundary_links.h"

#include <cmath>
#include <numbers>
#include <vector>

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

// A boundary round a cylinder of radius 40 mm (axis z) at height z = 0,
// region 0 below: drags up the cylinder cross it at angles 0 and 28 degrees
// (a 19.5 mm chord, inside the link's reach). The surface bows 1.2 mm off
// the chord in the middle, more than the corridor's 1 mm half-width, so a
// contradicting drag there lies within the corridor only when it is
// measured in the surface.
ChangeMark CylinderCrossing(double angle_deg, int drag) {
  const double a = angle_deg * std::numbers::pi / 180.0;
  ChangeMark m;
  m.position = {40.0 * std::cos(a), 40.0 * std::sin(a), 0.0};
  m.direction = Eigen::Vector3d::UnitZ();
  m.normal = {std::cos(a), std::sin(a), 0.0};
  m.before = 0;
  m.after = 1;
  m.drag = drag;
  return m;
}

std::vector<LabelledPoint> UpTheCylinder(double angle_deg, double z_from, double z_to, double z_change) {
  const double a = angle_deg * std::numbers::pi / 180.0;
  std::vector<LabelledPoint> data;
  for (double z = z_from; z <= z_to + 1e-9; z += 0.5) {
    data.push_back({{40.0 * std::cos(a), 40.0 * std::sin(a), z}, z < z_change ? 0 : 1});
  }
  return data;
}

TEST(BoundaryLinks, OnACurvedSurfaceADragAcrossTheChordsMiddleStillVetoesIt) {
  const std::vector<ChangeMark> marks = {CylinderCrossing(0.0, 0), CylinderCrossing(28.0, 1)};
  std::vector<LabelledPoint> data = UpTheCylinder(0.0, -8.0, 8.0, 0.0);
  const std::vector<LabelledPoint> other = UpTheCylinder(28.0, -8.0, 8.0, 0.0);
  data.insert(data.end(), other.begin(), other.end());
  int links = 0;
  BoundaryLinkPoints(marks, data, {}, &links);
  EXPECT_EQ(links, 1);  // uncontradicted, the chord is drawn
  // A third drag half-way round found region 0 up to z = 3: the boundary
  // does not run straight between the two crossings.
  const std::vector<LabelledPoint> middle = UpTheCylinder(14.0, -8.0, 3.0, 10.0);
  data.insert(data.end(), middle.begin(), middle.end());
  BoundaryLinkPoints(marks, data, {}, &links);
  EXPECT_EQ(links, 0);
}

}  // namespace
}  // namespace surfmap
