#include "server/map/boundary_corners.h"

#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "server/map/boundary_links.h"
#include "server/map/testing/patch_corner.h"

namespace surfmap {
namespace {

using Scene = testing::PatchScene;
using testing::PatchCorner;
using testing::PatchTruth;

// Every point farther than seed_offset_mm from the corner lies
// seed_offset_mm off the patch's true sides, on its own region's side (1e-9:
// rounding). At the corner itself the points lie on both sides' lines: their
// side is a matter of rounding.
void ExpectOnThePatchsTrueSides(const std::vector<LabelledPoint>& points) {
  const BoundaryLinkOptions o;
  for (const LabelledPoint& p : points) {
    if (p.point.head<2>().norm() <= o.seed_offset_mm + 1e-9) continue;
    const double to_side = std::min(std::abs(p.point.x()) + std::max(0.0, p.point.y()),
                                    std::abs(p.point.y()) + std::max(0.0, p.point.x()));
    EXPECT_NEAR(to_side, o.seed_offset_mm, 1e-9) << p.point.transpose();
    EXPECT_EQ(p.label, PatchTruth(p.point)) << p.point.transpose();
  }
}

TEST(BoundaryCorners, TheLastCrossingsOfTwoSidesAreJoinedThroughTheCornerOnTheirOwnSides) {
  const Scene scene = PatchCorner(5.0);
  int links = 0, corners = 0;
  const std::vector<LabelledPoint> points = BoundaryLinkPoints(scene.marks, scene.data, {}, &links, &corners);
  EXPECT_EQ(links, 2);
  EXPECT_EQ(corners, 1);
  ExpectOnThePatchsTrueSides(points);
  int near_corner = 0;
  for (const LabelledPoint& p : points) near_corner += p.point.head<2>().norm() < 1.0;
  EXPECT_GT(near_corner, 0) << "the corner itself carries points";
}

TEST(BoundaryCorners, DataOfTheOtherRegionInsideTheCornerVetoesIt) {
  Scene scene = PatchCorner(5.0);
  scene.data.push_back({{-1.5, -1.5, 0.0}, 0});  // the patch's corner is cut off after all
  int corners = -1;
  BoundaryLinkPoints(scene.marks, scene.data, {}, nullptr, &corners);
  EXPECT_EQ(corners, 0);
}

TEST(BoundaryCorners, ASideWhoseLastTwoCrossingsLieSideBySideStillMakesTheCorner) {
  // A third drag crosses the side x = 0 0.7 mm nearer the corner than the
  // nearest one: the chain's last link is shorter than min_corner_link_mm,
  // too short to say where the side runs on, but the chain behind it is not
  // (the bottle, seed 6: two drags crossed its patch's side 0.7 mm apart).
  Scene scene = PatchCorner(5.0);
  scene.Drag({0.0, -4.3, 0.0}, Eigen::Vector3d::UnitX());
  int links = 0, corners = -1;
  const std::vector<LabelledPoint> points = BoundaryLinkPoints(scene.marks, scene.data, {}, &links, &corners);
  EXPECT_EQ(links, 3);
  EXPECT_EQ(corners, 1);
  ExpectOnThePatchsTrueSides(points);
  BoundaryLinkOptions before;
  before.chain_ends_reach_past_short_links = false;
  BoundaryLinkPoints(scene.marks, scene.data, before, nullptr, &corners);
  EXPECT_EQ(corners, 0) << "the build before drops the end";
}

TEST(BoundaryCorners, EndsFartherFromTheCornerThanTheReachAreNotJoined) {
  BoundaryLinkOptions o;
  const Scene scene = PatchCorner(o.corner_reach_mm + 1.0);
  int corners = -1;
  BoundaryLinkPoints(scene.marks, scene.data, o, nullptr, &corners);
  EXPECT_EQ(corners, 0);
  o.corner_reach_mm = 0.0;  // off
  const Scene near = PatchCorner(5.0);
  BoundaryLinkPoints(near.marks, near.data, o, nullptr, &corners);
  EXPECT_EQ(corners, 0);
}

TEST(BoundaryCorners, EndsOnSurfacesThatTurnAwayFromEachOtherAreNotJoined) {
  // The side y = 0's crossings on a face tilted 70 degrees from the other
  // side's (a fold, or the far face of a thin object).
  Scene scene = PatchCorner(5.0);
  const double tilt = 70.0 * 3.14159265358979 / 180.0;
  for (int m : {2, 3}) {
    scene.marks[m].normal = {0.0, -std::sin(tilt), std::cos(tilt)};
    scene.marks[m].direction = {0.0, std::cos(tilt), std::sin(tilt)};  // along the tilted face
  }
  BoundaryLinkOptions any_normals;
  any_normals.max_corner_normal_deg = 180.0;
  int corners = -1;
  BoundaryLinkPoints(scene.marks, scene.data, any_normals, nullptr, &corners);
  ASSERT_EQ(corners, 1) << "without the normals' limit the corner is drawn";
  BoundaryLinkPoints(scene.marks, scene.data, {}, nullptr, &corners);
  EXPECT_EQ(corners, 0);
}

TEST(BoundaryCorners, ABoundaryThatRunsStraightOnIsNoCorner) {
  // Two chains along the same side x = 0 with a 30 mm gap: a straight run,
  // which links (not corners) are for.
  Scene scene;
  for (double y : {-40.0, -30.0, 0.0, 10.0}) scene.Drag({0.0, y, 0.0}, Eigen::Vector3d::UnitX());
  for (ChangeMark& m : scene.marks) m.before = 1, m.after = 0;
  for (LabelledPoint& p : scene.data) p.label = p.point.x() < 0.0 ? 1 : 0;
  int links = 0, corners = -1;
  BoundaryLinkPoints(scene.marks, scene.data, {}, &links, &corners);
  EXPECT_EQ(links, 2);
  EXPECT_EQ(corners, 0);
}

// A wedge of region 1 with its point at the origin, opening towards -y by
// 2 x half_deg; each side crossed 10, 16 and 22 mm from the point by drags
// perpendicular to it, from inside to out, with data 4 mm either side (a
// drag across one side 10 mm from a 24-degree point reaches the other side
// 4.45 mm in). Nearer each other than a side's two crossings, a crossing of
// one side and the other's would be linked across the wedge instead: a
// chord cutting the point off; and two crossings of each side alone lie on
// a circle (an isosceles trapezoid), which the dot rule would draw.
Scene Wedge(double half_deg) {
  const double h = half_deg * 3.14159265358979 / 180.0;
  const auto truth = [h](const Eigen::Vector3d& p) {
    return p.y() < 0.0 && std::abs(p.x()) < -p.y() * std::tan(h) ? 1 : 0;
  };
  Scene scene;
  scene.data_mm = 4.0;
  for (double side : {-1.0, 1.0}) {
    const Eigen::Vector3d along(side * std::sin(h), -std::cos(h), 0.0), out(side * std::cos(h), std::sin(h), 0.0);
    for (double d : {10.0, 16.0, 22.0}) {
      const Eigen::Vector3d at = d * along;
      scene.Drag(at, out);
      scene.marks.back().before = truth(at - 0.5 * out);
      scene.marks.back().after = truth(at + 0.5 * out);
    }
  }
  for (LabelledPoint& p : scene.data) p.label = truth(p.point);
  return scene;
}

TEST(BoundaryCorners, AWedgesSharpPointIsACornerUpToTheMaximumTurn) {
  // A label's triangle has 60-degree points (the boundary turns 120
  // degrees), a sliver's 30 (150): held_decals. A 45-degree point turns
  // 135 degrees, past the 120 that once bounded a corner.
  const Scene wedge = Wedge(22.5);
  int links = 0, corners = -1;
  const std::vector<LabelledPoint> points = BoundaryLinkPoints(wedge.marks, wedge.data, {}, &links, &corners);
  EXPECT_EQ(links, 4);
  EXPECT_EQ(corners, 1);
  int near_point = 0;
  for (const LabelledPoint& p : points) near_point += p.point.head<2>().norm() < 1.0;
  EXPECT_GT(near_point, 0) << "the point itself carries points";
  BoundaryLinkOptions before;
  before.max_corner_turn_deg = 120.0;
  BoundaryLinkPoints(wedge.marks, wedge.data, before, nullptr, &corners);
  EXPECT_EQ(corners, 0) << "the build before: no corner past 120 degrees";
  // A 24-degree point turns 156 degrees: past the maximum, where two
  // chain ends' straight runs on overshoot a round end or a hairpin.
  const Scene needle = Wedge(12.0);
  BoundaryLinkPoints(needle.marks, needle.data, {}, nullptr, &corners);
  EXPECT_EQ(corners, 0);
  BoundaryLinkOptions any_turn;
  any_turn.max_corner_turn_deg = 179.0;
  BoundaryLinkPoints(needle.marks, needle.data, any_turn, nullptr, &corners);
  EXPECT_EQ(corners, 1) << "only the turn refuses it";
}

// Three crossings of each side, the nearest 4 mm from the corner, by drags
// 25 degrees off perpendicular to their side towards the corner: within the
// link's 32 degrees of perpendicular both to the side and to the chord
// between the two nearest crossings, which is linked and cuts the corner.
// The patch's side x = 0 crossed at y = each of `on_x`, its side y = 0 at
// x = each of `on_y` (all < 0), by drags 25 degrees off perpendicular.
Scene ObliqueCrossings(const std::vector<double>& on_x, const std::vector<double>& on_y) {
  constexpr double kPi = 3.14159265358979;
  const double c = std::cos(25.0 * kPi / 180.0), s = std::sin(25.0 * kPi / 180.0);
  Scene scene;
  for (double at : on_x) scene.Drag({0.0, at, 0.0}, Eigen::Vector3d(c, s, 0.0));
  for (double at : on_y) scene.Drag({at, 0.0, 0.0}, Eigen::Vector3d(s, c, 0.0));
  return scene;
}

Scene CutCorner(int crossings_per_side) {
  std::vector<double> at;
  for (int k = 0; k < crossings_per_side; ++k) at.push_back(-4.0 - 8.0 * k);
  return ObliqueCrossings(at, at);
}

TEST(BoundaryCorners, ALinkThatCutsACornerBetweenStraightSidesIsReplacedByTheCorner) {
  const Scene scene = CutCorner(3);
  BoundaryLinkOptions no_cut;
  no_cut.max_corner_side_residual_mm = 0.0;  // off: the chord is drawn
  int links = 0, corners = -1;
  BoundaryLinkPoints(scene.marks, scene.data, no_cut, &links, &corners);
  ASSERT_EQ(links, 5) << "two along each side and the chord across the corner";
  EXPECT_EQ(corners, 0);

  const std::vector<LabelledPoint> points = BoundaryLinkPoints(scene.marks, scene.data, {}, &links, &corners);
  EXPECT_EQ(links, 4);
  EXPECT_EQ(corners, 1);
  ExpectOnThePatchsTrueSides(points);
  int in_corner_triangle = 0;
  for (const LabelledPoint& p : points) in_corner_triangle += p.point.x() + p.point.y() > -4.0 && p.label == 1;
  EXPECT_GT(in_corner_triangle, 0) << "the corner the chord cut off carries the patch's points";
}

TEST(BoundaryCorners, ACornerCutBetweenSidesOfOneLinkEachKeepsItsChord) {
  // One link per side says nothing of whether the sides run straight, even
  // where both chains end there (corner_side_may_end_its_chain).
  const Scene scene = CutCorner(2);
  int links = 0, corners = -1;
  BoundaryLinkPoints(scene.marks, scene.data, {}, &links, &corners);
  EXPECT_EQ(links, 3);
  EXPECT_EQ(corners, 0);
}

TEST(BoundaryCorners, ACornerCutBetweenSidesOfOneLinkWithinReachIsReplacedWhenTheChainRunsOnPastIt) {
  // Crossings 4, 16 and 32 mm from the corner on each side: one link of
  // each side within corner_side_reach_mm (20 mm) of the chord's ends, and
  // the next, past it, running straight on (the bottle, seed 6: links of
  // 13-17 mm).
  const Scene scene = ObliqueCrossings({-4.0, -16.0, -32.0}, {-4.0, -16.0, -32.0});
  BoundaryLinkOptions before;
  before.corner_side_checked_past_reach = false;
  int links = 0, corners = -1;
  BoundaryLinkPoints(scene.marks, scene.data, before, &links, &corners);
  ASSERT_EQ(links, 5) << "two along each side and the chord across the corner";
  EXPECT_EQ(corners, 0);
  const std::vector<LabelledPoint> points = BoundaryLinkPoints(scene.marks, scene.data, {}, &links, &corners);
  EXPECT_EQ(links, 4);
  EXPECT_EQ(corners, 1);
  ExpectOnThePatchsTrueSides(points);
}

TEST(BoundaryCorners, ACornerCutNextToASideOfOneLinkWhereItsChainEndsIsReplacedWhenTheOtherSideRunsStraight) {
  // The side x = 0 crossed 4, 12 and 20 mm from the corner; the side y = 0
  // only 4 and 16 mm from it, and nowhere beyond (the bottle, seeds 9 and
  // 14: a patch's top side crossed twice, 12-16 mm apart).
  const Scene scene = ObliqueCrossings({-4.0, -12.0, -20.0}, {-4.0, -16.0});
  BoundaryLinkOptions before;
  before.corner_side_may_end_its_chain = false;
  before.square_corner_from_one_side = false;  // else the lone side is drawn square
  int links = 0, corners = -1;
  BoundaryLinkPoints(scene.marks, scene.data, before, &links, &corners);
  ASSERT_EQ(links, 4) << "two along x = 0, one along y = 0 and the chord across the corner";
  EXPECT_EQ(corners, 0);
  const std::vector<LabelledPoint> points = BoundaryLinkPoints(scene.marks, scene.data, {}, &links, &corners);
  EXPECT_EQ(links, 3);
  EXPECT_EQ(corners, 1);
  ExpectOnThePatchsTrueSides(points);
}

TEST(BoundaryCorners, ACornerCutNextToASideCrossedOnceIsDrawnSquareToTheStraightSide) {
  // The side x = 0 crossed 4, 12 and 20 mm from the corner; the side y = 0
  // once, 4 mm from it (held_vase, seed 4: a drag-sized patch's bottom side
  // crossed at one place, and the chord from there to the straight side's
  // last crossing cut 8 % of the patch off). The side crossed once shows no
  // direction; it is taken square to the straight one.
  const Scene scene = ObliqueCrossings({-4.0, -12.0, -20.0}, {-4.0});
  BoundaryLinkOptions before;
  before.square_corner_from_one_side = false;
  int links = 0, corners = -1;
  BoundaryLinkPoints(scene.marks, scene.data, before, &links, &corners);
  ASSERT_EQ(links, 3) << "two along x = 0 and the chord across the corner";
  EXPECT_EQ(corners, 0);
  const std::vector<LabelledPoint> points = BoundaryLinkPoints(scene.marks, scene.data, {}, &links, &corners);
  EXPECT_EQ(links, 2);
  EXPECT_EQ(corners, 1);
  ExpectOnThePatchsTrueSides(points);
  // Two lone crossings, one of each side, still keep their chord: neither
  // side shows a direction to be square to.
  const Scene lone = ObliqueCrossings({-4.0}, {-4.0});
  BoundaryLinkPoints(lone.marks, lone.data, {}, &links, &corners);
  EXPECT_EQ(links, 1);
  EXPECT_EQ(corners, 0);
}

TEST(BoundaryCorners, ALinkAlongAStraightSideIsNeverTakenForACutCorner) {
  // Crossings 12, 24, 40 and 56 mm from the corner on x = 0, 12, 24 and 40
  // on y = 0: the chord between the nearest two cuts the corner, and the
  // link from (0, -12) up its side has a straight side beyond it and, at
  // (0, -12), a chain that turns along the chord. Drawn square, that link
  // would make a corner of no width nearer than the true one (the bottle,
  // seed 8) and take its crossing from it.
  // The crossings past the nearest lie 0.2 mm outside x = 0 (a change is
  // located to ~0.1-0.4 mm), so the nearest lies just off their line.
  Scene scene = ObliqueCrossings({-12.0, -24.0, -40.0, -56.0}, {-12.0, -24.0, -40.0});
  for (int k = 1; k <= 3; ++k) scene.marks[k].position.x() = 0.2;
  int links = 0, corners = -1;
  const std::vector<LabelledPoint> points = BoundaryLinkPoints(scene.marks, scene.data, {}, &links, &corners);
  EXPECT_EQ(corners, 1);
  int in_corner_triangle = 0;
  for (const LabelledPoint& p : points) in_corner_triangle += p.point.x() + p.point.y() > -12.0 && p.label == 1;
  EXPECT_GT(in_corner_triangle, 0) << "the corner the chord cut off carries the patch's points";
}

// A 16 mm square patch (region 1) in x, y in (-16, 0), crossed three times
// on its side x = 0 (at y = -3, -8, -13) and once on each of its sides y = 0
// and y = -16 (at x = -4), every drag 25 degrees off perpendicular to its
// side, each with its data every 0.5 mm for 8 mm either side.
int SmallSquareTruth(const Eigen::Vector3d& p) {
  return p.x() < 0.0 && p.x() > -16.0 && p.y() < 0.0 && p.y() > -16.0 ? 1 : 0;
}

Scene SmallSquarePatch() {
  constexpr double kPi = 3.14159265358979;
  const double c = std::cos(25.0 * kPi / 180.0), s = std::sin(25.0 * kPi / 180.0);
  Scene scene;
  scene.truth = SmallSquareTruth;
  scene.Drag({0.0, -3.0, 0.0}, {c, s, 0.0});
  scene.Drag({0.0, -8.0, 0.0}, {c, s, 0.0});
  scene.Drag({0.0, -13.0, 0.0}, {c, -s, 0.0});
  scene.Drag({-4.0, 0.0, 0.0}, {s, c, 0.0});
  scene.Drag({-4.0, -16.0, 0.0}, {s, -c, 0.0});
  return scene;
}

TEST(BoundaryCorners, ASmallPatchsSideIsStraightUpToItsNextCorner) {
  // Each corner of the side x = 0 is cut by a chord to the side crossed
  // once. Walked over corner_side_reach_mm (20 mm) from either end, the
  // straight side runs on round the patch's other corner (held_vase,
  // seed 4: a 14 mm patch); up to that turn it is two links of a line.
  const Scene scene = SmallSquarePatch();
  BoundaryLinkOptions before;
  before.corner_side_stops_at_next_corner = false;
  int links = 0, corners = -1;
  BoundaryLinkPoints(scene.marks, scene.data, before, &links, &corners);
  ASSERT_EQ(links, 4) << "two along x = 0 and a chord across each of its corners";
  EXPECT_EQ(corners, 0);
  const std::vector<LabelledPoint> points = BoundaryLinkPoints(scene.marks, scene.data, {}, &links, &corners);
  EXPECT_EQ(links, 2);
  EXPECT_EQ(corners, 2);
  int in_cut_corners = 0;
  for (const LabelledPoint& p : points) {
    // Beyond the chords (-4, 0)-(0, -3) and (0, -13)-(-4, -16), inside the patch.
    const bool top = p.point.x() < 0.0 && p.point.y() < 0.0 && 3.0 * p.point.x() + 4.0 * p.point.y() > -12.0;
    const bool bottom = p.point.x() < 0.0 && p.point.y() > -16.0 && 3.0 * p.point.x() - 4.0 * p.point.y() > 52.0;
    in_cut_corners += (top || bottom) && p.label == 1;
  }
  EXPECT_GT(in_cut_corners, 0) << "the corners the chords cut off carry the patch's points";
}

// `crossings` crossings, evenly spaced, of a circle of radius `radius` mm
// round the origin (region 1 inside) by radial drags, each with its data
// every 0.5 mm for 8 mm either side.
Scene RoundBoundary(double radius, int crossings) {
  constexpr double kPi = 3.14159265358979;
  Scene scene;
  for (int k = 0; k < crossings; ++k) {
    const double angle = 2.0 * kPi * k / crossings;
    const Eigen::Vector3d out(std::cos(angle), std::sin(angle), 0.0);
    ChangeMark m;
    m.position = radius * out;
    m.direction = out;
    m.before = 1;  // inside
    m.after = 0;
    m.drag = k;
    scene.marks.push_back(m);
    for (double s = -8.0; s <= 8.0; s += 0.5) {
      if (s != 0.0) scene.data.push_back({(radius + s) * out, s < 0.0 ? 1 : 0});
    }
  }
  return scene;
}

TEST(BoundaryCorners, ARoundBoundaryOfLongChordsKeepsThem) {
  // Fifteen crossings of a circle of radius 40 mm by radial drags: 16.6 mm
  // chords, so each side has one link within corner_side_reach_mm, and the
  // next turns from it by 24 degrees.
  const Scene circle = RoundBoundary(40.0, 15);
  const std::vector<ChangeMark>& marks = circle.marks;
  const std::vector<LabelledPoint>& data = circle.data;
  BoundaryLinkOptions loose;
  loose.max_line_turn_deg = 30.0;  // a 24-degree turn passes as running on
  int links = 0, corners = -1;
  BoundaryLinkPoints(marks, data, loose, &links, &corners);
  ASSERT_GT(corners, 0) << "with sides that need not run on, chords become corners";
  BoundaryLinkPoints(marks, data, {}, &links, &corners);
  EXPECT_EQ(links, 15);
  EXPECT_EQ(corners, 0);
}

TEST(BoundaryCorners, AnArcOfARoundBoundaryWhoseChainEndsKeepsItsChords) {
  // Five consecutive crossings of a circle of radius 20 mm, 30 degrees
  // apart (10.4 mm chords), by radial drags. The chain ends at both outer
  // crossings, so the chord next to each end has a side of one link where
  // the chain ends; the other side turns 30 degrees at every crossing and
  // is not straight.
  Scene arc = RoundBoundary(20.0, 12);
  const std::size_t data_per_drag = arc.data.size() / arc.marks.size();
  arc.marks.resize(5);
  arc.data.resize(5 * data_per_drag);
  BoundaryLinkOptions loose;
  loose.max_corner_side_residual_mm = 5.0;  // the arc's 2.7 mm sagitta passes as straight
  int links = 0, corners = -1;
  BoundaryLinkPoints(arc.marks, arc.data, loose, &links, &corners);
  ASSERT_GT(corners, 0) << "with a round side taken as straight, a chord next to a chain's end becomes a corner";
  BoundaryLinkPoints(arc.marks, arc.data, {}, &links, &corners);
  EXPECT_EQ(links, 4);
  EXPECT_EQ(corners, 0);
}

TEST(BoundaryCorners, DataOfTheOtherRegionInACutCornerKeepsTheChord) {
  Scene scene = CutCorner(3);
  scene.data.push_back({{-1.0, -1.0, 0.0}, 0});  // the corner is cut off after all
  int links = 0, corners = -1;
  BoundaryLinkPoints(scene.marks, scene.data, {}, &links, &corners);
  EXPECT_EQ(links, 5);
  EXPECT_EQ(corners, 0);
}

TEST(BoundaryCorners, ARoundBoundaryKeepsItsChords) {
  // Twelve crossings of a circle of radius 20 mm (too big for a dot), by
  // radial drags: each chord turns 30 degrees from the next, like the two
  // sides of a corner, but no side runs straight.
  const Scene circle = RoundBoundary(20.0, 12);
  const std::vector<ChangeMark>& marks = circle.marks;
  const std::vector<LabelledPoint>& data = circle.data;
  BoundaryLinkOptions loose;
  loose.max_corner_side_residual_mm = 5.0;  // the circle's 2.7 mm sagitta passes as straight
  int links = 0, corners = -1;
  BoundaryLinkPoints(marks, data, loose, &links, &corners);
  ASSERT_GT(corners, 0) << "with sides that need not run straight, chords become corners";
  BoundaryLinkPoints(marks, data, {}, &links, &corners);
  EXPECT_EQ(links, 12);
  EXPECT_EQ(corners, 0);
}

}  // namespace
}  // namespace surfmap
