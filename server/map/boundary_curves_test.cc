#include "server/map/boundary_curves.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

#include <gtest/gtest.h>
#include "server/map/testing/boundary_crossings.h"

namespace surfmap {
namespace {

// A round dot of radius kRadius on the plate z = 0, region 1 inside and
// region 0 outside, crossed by `count` radial drags evenly round it, each
// from outside in.
constexpr double kRadius = 12.0;

std::vector<ChangeMark> DotCrossings(int count) {
  std::vector<ChangeMark> marks;
  for (int k = 0; k < count; ++k) {
    const double a = 2.0 * std::numbers::pi * k / count;
    ChangeMark m;
    m.position = {kRadius * std::cos(a), kRadius * std::sin(a), 0.0};
    m.direction = -m.position.normalized();
    m.normal = Eigen::Vector3d::UnitZ();
    m.before = 0;
    m.after = 1;
    m.drag = k;
    marks.push_back(m);
  }
  return marks;
}

// Each drag's data, every 1 mm for 8 mm either side of its crossing.
std::vector<LabelledPoint> DotData(const std::vector<ChangeMark>& marks) {
  std::vector<LabelledPoint> data;
  for (const ChangeMark& m : marks) {
    for (double t = -8.0; t <= 8.0; t += 1.0) {
      if (t == 0.0) continue;
      const Eigen::Vector3d p = m.position + t * m.direction;
      data.push_back({p, p.norm() < kRadius ? 1 : 0});
    }
  }
  return data;
}

// How far the link points' midline (the mean of a point's two labels'
// positions is on the boundary drawn) strays from the true circle: the
// largest |r - kRadius| over the points, less their offset.
double LargestStrayMm(const std::vector<LabelledPoint>& points, const BoundaryLinkOptions& o) {
  double stray = 0.0;
  for (const LabelledPoint& p : points) stray = std::max(stray, std::abs(p.point.norm() - kRadius) - o.seed_offset_mm);
  return stray;
}

TEST(BoundaryCurves, ARoundDotIsDrawnRoundNotAsAPolygon) {
  // Eight crossings 45 degrees apart: chords of 9.2 mm, each cutting its
  // arc by a sagitta of 12 (1 - cos 22.5 degrees) = 0.91 mm.
  const std::vector<ChangeMark> marks = DotCrossings(8);
  const std::vector<LabelledPoint> data = DotData(marks);
  // The links alone: the dot's circle would replace them (boundary_dots.h).
  BoundaryLinkOptions curved;
  curved.max_dot_radius_mm = 0.0;
  curved.max_rectangle_side_mm = 0.0;  // eight crossings 45 degrees apart lie on a square too
  BoundaryLinkOptions chords = curved;
  chords.max_curve_turn_deg = 0.0;
  int links_curved = 0, links_chords = 0;
  const std::vector<LabelledPoint> round = BoundaryLinkPoints(marks, data, curved, &links_curved);
  const std::vector<LabelledPoint> polygon = BoundaryLinkPoints(marks, data, chords, &links_chords);
  ASSERT_EQ(links_curved, 8);
  ASSERT_EQ(links_chords, 8);
  // The cubic through a 45-degree arc leaves the circle by ~0.01 R; 0.15 mm
  // is half the change's own location error.
  EXPECT_LT(LargestStrayMm(round, curved), 0.15);
  EXPECT_GT(LargestStrayMm(polygon, chords), 0.8);
  // Every point stays on its own side of the true circle.
  for (const LabelledPoint& p : round) EXPECT_EQ(p.label, p.point.norm() < kRadius ? 1 : 0);
}

TEST(BoundaryCurves, AStraightChainStaysStraight) {
  const std::vector<ChangeMark> marks = {testing::Crossing(0.0, 0), testing::Crossing(10.0, 1),
                                         testing::Crossing(20.0, 2)};
  const BoundaryLinkOptions o;
  int links = 0;
  const std::vector<LabelledPoint> points = BoundaryLinkPoints(marks, testing::DragData(marks), o, &links);
  ASSERT_EQ(links, 2);
  for (const LabelledPoint& p : points) EXPECT_NEAR(std::abs(p.point.x()), o.seed_offset_mm, 1e-9);
}

TEST(BoundaryCurves, DataInsideTheCurvesBulgeKeepsThatLinkAChord) {
  const std::vector<ChangeMark> marks = DotCrossings(8);
  std::vector<LabelledPoint> data = DotData(marks);
  // Region 0 measured 0.5 mm inside the circle midway between crossings 0
  // and 1 (where the curve runs, 0.41 mm outside the chord): the boundary
  // there is not round, so that link is drawn straight.
  const double mid = std::numbers::pi / 8.0;
  data.push_back({(kRadius - 0.5) * Eigen::Vector3d(std::cos(mid), std::sin(mid), 0.0), 0});
  const BoundaryLinkOptions o;
  std::vector<DrawnLink> links;
  for (int k = 0; k < 8; ++k) {
    const int next = (k + 1) % 8;
    const Eigen::Vector3d middle = 0.5 * (marks[k].position + marks[next].position);
    links.push_back({k, next, 0, 1, Eigen::Vector3d(middle.normalized())});  // region 0 outside
  }
  int curved = 0;
  const std::vector<LabelledPoint> points = LinkSeeds(marks, links, LabelledPointGrid(data, 2.0), o, &curved);
  EXPECT_EQ(curved, 7);
  // The chord's middle runs 0.91 mm inside the circle, the curve's within
  // 0.15 mm of it: both labels' points there lie inside 11.5 mm.
  const bool chord_drawn = std::any_of(points.begin(), points.end(), [&](const LabelledPoint& p) {
    const double angle = std::atan2(p.point.y(), p.point.x());
    return std::abs(angle - mid) < 0.05 && p.point.norm() < kRadius * std::cos(mid) + o.seed_offset_mm + 0.1 &&
           p.label == 0;
  });
  EXPECT_TRUE(chord_drawn);
}

TEST(BoundaryCurves, ACrossingOffItsBoundaryBendsNoNeighbouringLink) {
  // Crossings every 10 mm up the boundary x = 0, the middle one located
  // 1.5 mm off it: the chain zigzags there. Link 1-2 runs straight at 1 and
  // turns towards the stray crossing at 2; a curve would leave x = 0 along
  // all of it, a chord only where it meets the stray one.
  std::vector<ChangeMark> marks;
  for (int k = 0; k < 7; ++k) marks.push_back(testing::Crossing(10.0 * k, k));
  marks[3].position.x() = 1.5;
  std::vector<DrawnLink> links;
  for (int k = 0; k + 1 < 7; ++k) links.push_back({k, k + 1, 0, 1, Eigen::Vector3d(-1.0, 0.0, 0.0)});
  const BoundaryLinkOptions o;
  int curved = -1;
  const std::vector<LabelledPoint> points = LinkSeeds(marks, links, LabelledPointGrid({}, 2.0), o, &curved);
  EXPECT_EQ(curved, 0);
  for (const LabelledPoint& p : points) {
    // Between crossings 1 and 2 (y in [10, 20]) every point is on the chord x = 0.
    if (p.point.y() >= 10.0 && p.point.y() <= 20.0) {
      EXPECT_NEAR(std::abs(p.point.x()), o.seed_offset_mm, 1e-9);
    }
  }
}

TEST(BoundaryCurves, AChainTurningMoreThanTheLimitIsDrawnInChords) {
  // The dot's chain turns 45 degrees at each crossing.
  const std::vector<ChangeMark> marks = DotCrossings(8);
  BoundaryLinkOptions o;
  o.max_dot_radius_mm = 0.0;  // the links alone, not the dot's circle (boundary_dots.h)
  o.max_rectangle_side_mm = 0.0;  // nor the square its crossings lie on (boundary_rectangles.h)
  o.max_curve_turn_deg = 40.0;
  EXPECT_GT(LargestStrayMm(BoundaryLinkPoints(marks, DotData(marks), o), o), 0.8);
  o.max_curve_turn_deg = 50.0;
  EXPECT_LT(LargestStrayMm(BoundaryLinkPoints(marks, DotData(marks), o), o), 0.15);
}

}  // namespace
}  // namespace surfmap
