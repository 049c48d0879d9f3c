#include "server/map/boundary_rectangles.h"

#include <cmath>
#include <functional>
#include <numbers>
#include <string>
#include <vector>

#include <gtest/gtest.h>

namespace surfmap {
namespace {
namespace rectangles_test {  // the map's tests build as one unit

constexpr int kOutside = 0;
constexpr int kPatch = 1;
constexpr double kTurn = 30.0 * std::numbers::pi / 180.0;  // the patch's turn in the plane z = 0

// Plane coordinates of a point given in the patch's own frame (u along its
// 24 mm side).
Eigen::Vector3d Patch(double u, double v) {
  return {u * std::cos(kTurn) - v * std::sin(kTurn), u * std::sin(kTurn) + v * std::cos(kTurn), 0.0};
}

// A drag entering the patch at (u, v) on its edge, running inwards along
// the patch-frame direction (du, dv).
ChangeMark Crossing(double u, double v, double du, double dv, int drag) {
  ChangeMark m;
  m.position = Patch(u, v);
  m.direction = (Patch(du, dv)).normalized();
  m.normal = Eigen::Vector3d::UnitZ();
  m.before = kOutside;
  m.after = kPatch;
  m.drag = drag;
  return m;
}

// Every crossing's drag, data every 0.5 mm for 8 mm either side, labelled
// by `inside` (patch-frame coordinates).
std::vector<LabelledPoint> DragData(const std::vector<ChangeMark>& marks,
                                    const std::function<bool(double, double)>& inside) {
  std::vector<LabelledPoint> data;
  for (const ChangeMark& m : marks) {
    for (double t = -8.0; t <= 8.0; t += 0.5) {
      if (std::abs(t) < 0.3) continue;  // the change's own guard
      const Eigen::Vector3d p = m.position + t * m.direction;
      const double u = p.x() * std::cos(kTurn) + p.y() * std::sin(kTurn);
      const double v = -p.x() * std::sin(kTurn) + p.y() * std::cos(kTurn);
      data.push_back({p, inside(u, v) ? kPatch : kOutside});
    }
  }
  return data;
}

bool InRectangle(double u, double v) { return std::abs(u) < 12.0 && std::abs(v) < 8.0; }

// A 24 x 16 mm label's crossings: two on each long side, one on each short
// side and two more, as scan_handle_m seed 1's were (each drag oblique).
std::vector<ChangeMark> LabelCrossings() {
  return {Crossing(-12.0, 3.0, 1.0, -0.6, 0), Crossing(-12.0, -5.0, 1.0, 0.5, 1),  // left
          Crossing(12.0, -2.0, -1.0, 0.8, 2),                                     // right
          Crossing(-6.0, 8.0, 0.5, -1.0, 3),  Crossing(4.0, 8.0, -0.7, -1.0, 4),    // top
          Crossing(-2.0, -8.0, -0.9, 1.0, 5), Crossing(7.0, -8.0, 0.3, 1.0, 6)};    // bottom
}

std::vector<BoundaryOutline> Rectangles(const std::vector<ChangeMark>& marks, const std::vector<LabelledPoint>& data,
                                        const BoundaryLinkOptions& o = {}) {
  return FindRectangles(marks, LabelledPointGrid(data, 5.0), o, {});
}

TEST(BoundaryRectangles, ALabelsCrossingsOnItsFourSidesDrawItsRectangleCornersAndAll) {
  const std::vector<ChangeMark> marks = LabelCrossings();
  const std::vector<BoundaryOutline> found = Rectangles(marks, DragData(marks, InRectangle));
  ASSERT_EQ(found.size(), 1u);
  EXPECT_EQ(found[0].inner, kPatch);
  EXPECT_EQ(found[0].outer, kOutside);
  EXPECT_EQ(found[0].marks.size(), marks.size());
  EXPECT_NEAR(found[0].project_along.norm(), 1.0, 1e-9);
  EXPECT_NEAR(std::abs(found[0].project_along.z()), 1.0, 1e-9);
  // Its chords run along the true sides: every chord end within 0.05 mm of
  // the label's edge, and the corners drawn (a chord end near each).
  int near_corner = 0;
  for (const BoundarySegment& chord : found[0].chords) {
    for (const Eigen::Vector3d& p : {chord.p, chord.q}) {
      const double u = p.x() * std::cos(kTurn) + p.y() * std::sin(kTurn);
      const double v = -p.x() * std::sin(kTurn) + p.y() * std::cos(kTurn);
      EXPECT_LT(std::min(std::abs(std::abs(u) - 12.0), std::abs(std::abs(v) - 8.0)), 0.05) << u << " " << v;
      EXPECT_LT(std::max(std::abs(u) - 12.0, std::abs(v) - 8.0), 0.05) << u << " " << v;
      if (std::abs(std::abs(u) - 12.0) < 0.1 && std::abs(std::abs(v) - 8.0) < 0.1) ++near_corner;
    }
    EXPECT_EQ(chord.a, kPatch);
    EXPECT_GT(chord.towards_a.dot(-0.5 * (chord.p + chord.q)), 0.0) << "inwards";
  }
  EXPECT_GE(near_corner, 8);  // two chord ends at each of four corners
  BoundaryLinkOptions off;
  off.max_rectangle_side_mm = 0.0;
  EXPECT_TRUE(Rectangles(marks, DragData(marks, InRectangle), off).empty());
}

TEST(BoundaryRectangles, TooFewCrossingsOrASideNeverCrossedDrawNothing) {
  std::vector<ChangeMark> marks = LabelCrossings();
  marks.pop_back();
  marks.pop_back();  // five: no more than a rectangle's parameters
  EXPECT_TRUE(Rectangles(marks, DragData(marks, InRectangle)).empty());
  // Six crossings, none on the right side: a longer rectangle fits as well.
  marks = LabelCrossings();
  marks.erase(marks.begin() + 2);
  marks.push_back(Crossing(0.0, 8.0, 0.0, -1.0, 7));
  EXPECT_TRUE(Rectangles(marks, DragData(marks, InRectangle)).empty());
}

TEST(BoundaryRectangles, ASideCrossedOnlyAtACornerIsDrawnWhenDataRunAlongItOutside) {
  // A label crossed three times on its top side, once each on its left and
  // right, and once at its bottom right corner; a drag of the other region
  // ran along the bottom side 0.3 mm outside.
  const std::vector<ChangeMark> marks = {
      Crossing(-12.0, 1.0, 1.0, -0.4, 0),   Crossing(12.0, 2.0, -1.0, 0.2, 1),   Crossing(-8.0, 8.0, 0.3, -1.0, 2),
      Crossing(0.0, 8.0, -0.2, -1.0, 3),    Crossing(7.0, 8.0, 0.4, -1.0, 4),    Crossing(11.6, -8.0, -0.7, 1.0, 5)};
  std::vector<LabelledPoint> data = DragData(marks, InRectangle);
  EXPECT_TRUE(Rectangles(marks, data).empty()) << "nothing holds the bottom side";
  std::vector<LabelledPoint> along_bottom = data;
  for (double u = -10.0; u <= 10.0; u += 0.5) along_bottom.push_back({Patch(u, -8.3), kOutside});
  const std::vector<BoundaryOutline> found = Rectangles(marks, along_bottom);
  ASSERT_EQ(found.size(), 1u);
  int bottom = 0;
  for (const BoundarySegment& chord : found[0].chords) {
    const Eigen::Vector3d mid = 0.5 * (chord.p + chord.q);
    const double v = -mid.x() * std::sin(kTurn) + mid.y() * std::cos(kTurn);
    if (v > -7.9) continue;  // the left and right sides' chords end at -8 too
    ++bottom;
    EXPECT_NEAR(v, -8.0, 0.05);
  }
  EXPECT_GE(bottom, 20) << "the bottom side drawn along its 24 mm";
  BoundaryLinkOptions before;
  before.rectangle_sides_closed_by_data = false;
  EXPECT_TRUE(Rectangles(marks, along_bottom, before).empty());
  // Data along a quarter of it leave the rest of the side free.
  std::vector<LabelledPoint> quarter = data;
  for (double u = -10.0; u <= -4.0; u += 0.5) quarter.push_back({Patch(u, -8.3), kOutside});
  EXPECT_TRUE(Rectangles(marks, quarter).empty());
}

TEST(BoundaryRectangles, AnLOrARoundPatchIsNoRectangle) {
  // An L: the 24 x 16 label less its top right 12 x 8 quarter, crossed on
  // its inner corner's two sides as well.
  auto in_l = [](double u, double v) { return InRectangle(u, v) && !(u > 0.0 && v > 0.0); };
  std::vector<ChangeMark> l = LabelCrossings();
  l[2] = Crossing(12.0, -4.0, -1.0, 0.3, 2);
  l[4] = Crossing(6.0, 0.0, -0.3, -1.0, 4);  // the inner corner's bottom side
  l.push_back(Crossing(0.0, 4.0, -1.0, 0.2, 7));  // ... and its left side
  EXPECT_TRUE(Rectangles(l, DragData(l, in_l)).empty());
  // A round patch of radius 8 crossed at eight places. Its crossings lie
  // within max_dot_residual_mm of a rectangle's sides as well (two on each,
  // the arc between them bowing out 1 mm where no drag ran): the links look
  // for dots first and give FindRectangles the dots' marks as taken.
  std::vector<ChangeMark> round;
  for (double deg : {10.0, 50.0, 100.0, 160.0, 200.0, 250.0, 290.0, 330.0}) {
    const double a = deg * std::numbers::pi / 180.0;
    round.push_back(Crossing(8.0 * std::cos(a), 8.0 * std::sin(a), -std::cos(a), -std::sin(a), round.size()));
  }
  const std::vector<LabelledPoint> data = DragData(round, [](double u, double v) { return std::hypot(u, v) < 8.0; });
  int dots = 0, rectangles = 0;
  BoundaryLinkPoints(round, data, {}, nullptr, nullptr, nullptr, &dots, &rectangles);
  EXPECT_EQ(dots, 1);
  EXPECT_EQ(rectangles, 0);
  BoundaryLinkOptions no_dots;
  no_dots.max_dot_radius_mm = 0.0;
  BoundaryLinkPoints(round, data, no_dots, nullptr, nullptr, nullptr, &dots, &rectangles);
  EXPECT_EQ(rectangles, 1) << "without the dot's circle first, a rectangle fits its crossings";
}

TEST(BoundaryRectangles, DataAgainstTheRectangleRefuseItOrLeaveOutItsChords) {
  const std::vector<ChangeMark> marks = LabelCrossings();
  // Another region's data inside it: it is a frame, or no rectangle.
  std::vector<LabelledPoint> data = DragData(marks, InRectangle);
  data.push_back({Patch(0.0, 0.0), kOutside});
  EXPECT_TRUE(Rectangles(marks, data).empty());
  // Its own region 3 mm outside it: the patch is larger, or not square.
  data = DragData(marks, InRectangle);
  data.push_back({Patch(0.0, 11.0), kPatch});
  EXPECT_TRUE(Rectangles(marks, data).empty());
  // Its own region 0.8 mm out beside one side: the chords there are left
  // out, the rest drawn.
  data = DragData(marks, InRectangle);
  const std::size_t all = Rectangles(marks, data).at(0).chords.size();
  data.push_back({Patch(0.0, -8.8), kPatch});
  const std::vector<BoundaryOutline> found = Rectangles(marks, data);
  ASSERT_EQ(found.size(), 1u);
  EXPECT_LT(found[0].chords.size(), all);
  EXPECT_GE(found[0].chords.size(), all - 2);
}

TEST(BoundaryRectangles, DataOnAnotherSheetOfTheObjectBelowThePatchDoNotRefuseIt) {
  // The label on a handle: under its plane, 4 and 8 mm down, lie the
  // handle's far side and its butt (scan_handle_m through the service,
  // seed 2), read as another region.
  const std::vector<ChangeMark> marks = LabelCrossings();
  std::vector<LabelledPoint> data = DragData(marks, InRectangle);
  for (double off : {-4.0, -8.0}) data.push_back({Patch(-10.0, -6.5) + Eigen::Vector3d(0.0, 0.0, off), kOutside});
  EXPECT_EQ(Rectangles(marks, data).size(), 1u);
  BoundaryLinkOptions before;
  before.rectangle_data_on_patch_sheet = false;
  EXPECT_TRUE(Rectangles(marks, data, before).empty()) << "the build before: data 12 mm off still checked it";
  // 1.5 mm off the plane is the patch's own sheet (within 2 corridor_mm of
  // its crossings, all in the plane here): still against it.
  data.push_back({Patch(0.0, 0.0) + Eigen::Vector3d(0.0, 0.0, -1.5), kOutside});
  EXPECT_TRUE(Rectangles(marks, data).empty());
}

TEST(BoundaryRectangles, OptionsRefuseFewerCrossingsThanARectanglesParametersByName) {
  BoundaryLinkOptions options;
  options.min_rectangle_crossings = 4;
  std::string why;
  EXPECT_FALSE(options.IsValid(&why));
  EXPECT_NE(why.find("min_rectangle_crossings"), std::string::npos) << why;
  options = {};
  options.max_rectangle_side_mm = -1.0;
  EXPECT_FALSE(options.IsValid(&why));
  EXPECT_NE(why.find("max_rectangle_side_mm"), std::string::npos) << why;
}

}  // namespace rectangles_test
}  // namespace
}  // namespace surfmap
