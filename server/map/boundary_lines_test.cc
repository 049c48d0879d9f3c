#include "server/map/boundary_lines.h"

#include <cmath>
#include <numbers>

#include <gtest/gtest.h>
#include "server/map/boundary_links.h"
#include "server/map/testing/boundary_crossings.h"

namespace surfmap {
namespace {

using testing::Crossing;
using testing::DragData;
using testing::LinksDrawn;

BoundaryLinkOptions WithoutLines() {
  BoundaryLinkOptions o;
  o.max_line_turn_deg = 0.0;
  return o;
}

TEST(BoundaryLines, ThreeObliqueCrossingsInARowAreJoined) {
  // 40-60 degrees off perpendicular: too oblique for a link of their own.
  const std::vector<ChangeMark> marks = {Crossing(0.0, 0, 45.0), Crossing(12.0, 1, -50.0),
                                         Crossing(24.0, 2, 60.0)};
  EXPECT_EQ(LinksDrawn(marks, WithoutLines()), 0);
  EXPECT_EQ(LinksDrawn(marks), 2);
  // Two say nothing of the boundary's direction.
  EXPECT_EQ(LinksDrawn({Crossing(0.0, 0, 45.0), Crossing(12.0, 1, -50.0)}), 0);
}

TEST(BoundaryLines, CrossingsAFewMillimetresApartAreJoinedWhenTheLineSpansACornerLink) {
  // One side of a drag-sized patch crossed three times, 4.2 and 2.5 mm
  // apart (held_vase, seed 10).
  const std::vector<ChangeMark> marks = {Crossing(0.0, 0, 45.0), Crossing(4.2, 1, -50.0), Crossing(6.7, 2, 40.0)};
  EXPECT_EQ(LinksDrawn(marks), 2);
  BoundaryLinkOptions before;
  before.min_line_chord_mm = before.min_corner_link_mm;
  EXPECT_EQ(LinksDrawn(marks, before), 0);
  // Three crossings within less than a corner link of each other do not
  // fix the side's direction.
  EXPECT_EQ(LinksDrawn({Crossing(0.0, 0, 45.0), Crossing(1.8, 1, -50.0), Crossing(3.6, 2, 40.0)}), 0);
  // Nor does a chord shorter than the shortest a line may have.
  EXPECT_EQ(LinksDrawn({Crossing(0.0, 0, 45.0), Crossing(5.0, 1, -50.0), Crossing(6.0, 2, 40.0)}), 0);
}

TEST(BoundaryLines, ALineIsCarriedOnAsAChain) {
  // A fourth crossing 28 mm on, beyond a link's reach: the chain's extension.
  const std::vector<ChangeMark> marks = {Crossing(0.0, 0, 45.0), Crossing(12.0, 1, -50.0),
                                         Crossing(24.0, 2, 60.0), Crossing(52.0, 3, 40.0)};
  EXPECT_EQ(LinksDrawn(marks), 3);
}

TEST(BoundaryLines, CrossingsInARowMakeAChainNotAWeb) {
  const std::vector<ChangeMark> marks = {Crossing(0.0, 0, 45.0), Crossing(8.0, 1, -45.0), Crossing(16.0, 2, 45.0),
                                         Crossing(24.0, 3, -45.0)};
  EXPECT_EQ(LinksDrawn(marks), 3);
}

TEST(BoundaryLines, APatchCornerIsNotCutAcross) {
  // The boundary turns by 90 degrees at (0, 14) and runs on along y = 14;
  // a drag along -y crosses that side at (6, 14): 56 degrees of turn at
  // the middle crossing.
  std::vector<ChangeMark> marks = {Crossing(0.0, 0, 45.0), Crossing(10.0, 1, -45.0)};
  ChangeMark side;
  side.position = {6.0, 14.0, 0.0};
  side.direction = {0.0, -1.0, 0.0};
  side.normal = Eigen::Vector3d::UnitZ();
  side.before = 0;
  side.after = 1;
  side.drag = 2;
  marks.push_back(side);
  EXPECT_EQ(LinksDrawn(marks), 0);
  BoundaryLinkOptions any_turn;
  any_turn.max_line_turn_deg = 90.0;
  EXPECT_EQ(LinksDrawn(marks, any_turn), 2);  // only the turn tells
}

TEST(BoundaryLines, ADotSmallerThanADragIsNotMadeAPolygon) {
  // Three crossings 60 degrees apart round a dot of radius 8 mm, each drag
  // running 45 degrees off the radius: 60 degrees of turn at the middle one.
  std::vector<ChangeMark> marks;
  for (int k = 0; k < 3; ++k) {
    const double phi = k * std::numbers::pi / 3.0, off = std::numbers::pi / 4.0;
    ChangeMark m;
    m.position = {8.0 * std::cos(phi), 8.0 * std::sin(phi), 0.0};
    m.direction = {-std::cos(phi + off), -std::sin(phi + off), 0.0};  // inwards: from region 0 into the dot
    m.normal = Eigen::Vector3d::UnitZ();
    m.before = 0;
    m.after = 1;
    m.drag = k;
    marks.push_back(m);
  }
  int with_lines = 0, without = 0;
  BoundaryLinkPoints(marks, {}, {}, &with_lines);
  BoundaryLinkPoints(marks, {}, WithoutLines(), &without);
  EXPECT_EQ(with_lines, without);
}

TEST(BoundaryLines, GrazingDragsOrDataAgainstTheLineStopIt) {
  // 85 degrees off perpendicular: along the boundary more than across it.
  EXPECT_EQ(LinksDrawn({Crossing(0.0, 0, 45.0), Crossing(12.0, 1, 85.0), Crossing(24.0, 2, 45.0)}), 0);
  // Region A on the other side at the middle crossing: not one boundary.
  ChangeMark reversed = Crossing(12.0, 1, -50.0);
  std::swap(reversed.before, reversed.after);
  EXPECT_EQ(LinksDrawn({Crossing(0.0, 0, 45.0), reversed, Crossing(24.0, 2, 60.0)}), 0);

  const std::vector<ChangeMark> marks = {Crossing(0.0, 0, 45.0), Crossing(12.0, 1, -50.0),
                                         Crossing(24.0, 2, 60.0)};
  std::vector<LabelledPoint> data = DragData(marks);
  data.push_back({{-0.8, 6.0, 0.0}, 1});  // region 1 found 0.8 mm on region 0's side
  int links = 0;
  BoundaryLinkPoints(marks, data, {}, &links);
  EXPECT_EQ(links, 0);
}

TEST(BoundaryLines, AMiddleCrossingUpToTheLineLimitOffPerpendicularCounts) {
  // 78 degrees off: held_palette's brass strip edge (seed 2 through the
  // service) was crossed 75.5 degrees off in the middle of its line.
  const std::vector<ChangeMark> marks = {Crossing(0.0, 0, 45.0), Crossing(12.0, 1, 78.0), Crossing(24.0, 2, 45.0)};
  EXPECT_EQ(LinksDrawn(marks), 2);
  BoundaryLinkOptions before;
  before.max_line_crossing_deg = 75.0;
  EXPECT_EQ(LinksDrawn(marks, before), 0);
}

TEST(BoundaryLines, TheLinksHaveRegionAOnItsSide) {
  const std::vector<ChangeMark> marks = {Crossing(0.0, 0, 45.0), Crossing(12.0, 1, -50.0),
                                         Crossing(24.0, 2, 60.0)};
  const LabelledPointGrid grid(DragData(marks), 5.0);
  const std::vector<DrawnLink> out = DrawLines(marks, {}, grid, {});
  ASSERT_EQ(out.size(), 2u);
  for (const DrawnLink& link : out) {
    EXPECT_EQ(link.to, 1);  // the middle crossing
    EXPECT_EQ(link.a, 0);
    EXPECT_EQ(link.b, 1);
    EXPECT_NEAR(link.towards_a.x(), -1.0, 1e-9);
  }
}

// A strip 0 < x < 7 (region 1) in region 0. Its edge x = 0 is crossed by
// three drags 40-65 degrees off perpendicular at y = 0, 12 and 24; the drag
// at y = 12 and one leaving the strip through its far edge at (7, 13.5),
// both running nearly along it, are consistent with a boundary across the
// strip between them. `hanging`: nothing else links (7, 13.5); otherwise a
// fourth crossing on from it (no data of its own) makes that chord part of
// a chain.
int LinksAcrossAStrip(bool hanging, const BoundaryLinkOptions& o) {
  auto crossing = [](double x, double y, double deg, int before, int drag) {
    ChangeMark m;
    m.position = {x, y, 0.0};
    m.direction = {std::cos(deg * std::numbers::pi / 180.0), std::sin(deg * std::numbers::pi / 180.0), 0.0};
    m.normal = Eigen::Vector3d::UnitZ();
    m.before = before;
    m.after = 1 - before;
    m.drag = drag;
    return m;
  };
  std::vector<ChangeMark> marks = {crossing(0.0, 0.0, 45.0, 0, 0), crossing(0.0, 12.0, -65.0, 0, 1),
                                   crossing(0.0, 24.0, 60.0, 0, 2), crossing(7.0, 13.5, 80.0, 1, 3)};
  std::vector<LabelledPoint> data;
  for (const ChangeMark& m : marks) {
    for (double t = -8.0; t <= 8.0; t += 1.0) {
      const Eigen::Vector3d p = m.position + t * m.direction;
      if (t != 0.0) data.push_back({p, p.x() > 0.0 && p.x() < 7.0 ? 1 : 0});
    }
  }
  if (!hanging) marks.push_back(crossing(14.0, 15.0, 80.0, 1, 4));
  int links = 0;
  BoundaryLinkPoints(marks, data, o, &links);
  return links;
}

TEST(BoundaryLines, ALineTakesAMarksSideFromAHangingLinkAcrossAStrip) {
  BoundaryLinkOptions keep;
  keep.min_hanging_link_angle_deg = 90.0;
  EXPECT_EQ(LinksAcrossAStrip(true, WithoutLines()), 1);  // the chord across the strip
  EXPECT_EQ(LinksAcrossAStrip(true, keep), 1);            // it holds the middle crossing's side
  EXPECT_EQ(LinksAcrossAStrip(true, {}), 2);              // the edge's line, and no chord across
  // The chord runs 78 degrees off the line: with 80 it is kept too.
  BoundaryLinkOptions steeper;
  steeper.min_hanging_link_angle_deg = 80.0;
  EXPECT_EQ(LinksAcrossAStrip(true, steeper), 1);
  // A chord that is part of a chain is not displaced.
  EXPECT_EQ(LinksAcrossAStrip(false, {}), 2);
  EXPECT_EQ(LinksAcrossAStrip(false, keep), 2);
}

}  // namespace
}  // namespace surfmap
