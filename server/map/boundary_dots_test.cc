#include "server/map/boundary_dots.h"

#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include "server/map/boundary_links.h"
#include "server/map/testing/patch_corner.h"

namespace surfmap {
namespace {

constexpr int kOutside = 0;
constexpr int kDot = 1;

// A drag crossing the edge of a dot of radius r centred at the origin of the
// plate z = 0, at polar angle phi, entering it (from region 0 into region 1)
// `off_deg` off the radius.
ChangeMark DotCrossing(double r, double phi_deg, int drag, double off_deg = 0.0) {
  const double phi = phi_deg * std::numbers::pi / 180.0, off = off_deg * std::numbers::pi / 180.0;
  ChangeMark m;
  m.position = {r * std::cos(phi), r * std::sin(phi), 0.0};
  m.direction = {-std::cos(phi + off), -std::sin(phi + off), 0.0};
  m.normal = Eigen::Vector3d::UnitZ();
  m.before = kOutside;
  m.after = kDot;
  m.drag = drag;
  return m;
}

// Each crossing's drag data every 1 mm for 8 mm either side, labelled by
// the true dot of radius r.
std::vector<LabelledPoint> DotData(const std::vector<ChangeMark>& marks, double r) {
  std::vector<LabelledPoint> data;
  for (const ChangeMark& m : marks) {
    for (double t = -8.0; t <= 8.0; t += 1.0) {
      const Eigen::Vector3d p = m.position + t * m.direction;
      if (std::abs(p.norm() - r) < 0.3) continue;  // the change's own guard
      data.push_back({p, p.norm() < r ? kDot : kOutside});
    }
  }
  return data;
}

// The dot's points labelled kDot: their largest and smallest distance from
// the centre.
std::pair<double, double> InnerSeedRadii(const std::vector<LabelledPoint>& points) {
  double lo = 1e9, hi = 0.0;
  for (const LabelledPoint& p : points) {
    if (p.label != kDot) continue;
    lo = std::min(lo, p.point.norm());
    hi = std::max(hi, p.point.norm());
  }
  return {lo, hi};
}

// The labelled points of the dots found (*dots: how many).
std::vector<LabelledPoint> Dots(const std::vector<ChangeMark>& marks, const std::vector<LabelledPoint>& data,
                                int* dots, const BoundaryLinkOptions& o = {}) {
  const std::vector<BoundaryDot> found = FindDots(marks, LabelledPointGrid(data, 5.0), o);
  *dots = static_cast<int>(found.size());
  std::vector<LabelledPoint> points;
  for (const BoundaryDot& dot : found) {
    EXPECT_EQ(dot.inner, kDot);
    EXPECT_EQ(dot.outer, kOutside);
    for (const BoundarySegment& chord : dot.chords) AppendSegmentSeeds(chord, o, &points);
  }
  return points;
}

// The marks round a dot of radius 7 mm draw one circle: its inner points lie
// inside it by the seed offset, less the chords' sagitta (1 mm chords on
// 7 mm: 0.02 mm).
void ExpectTheCircleOfRadius7(const std::vector<ChangeMark>& marks) {
  int dots = 0;
  const std::vector<LabelledPoint> points = Dots(marks, DotData(marks, 7.0), &dots);
  EXPECT_EQ(dots, 1);
  const auto [lo, hi] = InnerSeedRadii(points);
  EXPECT_NEAR(lo, 7.0 - 0.25, 0.05);
  EXPECT_NEAR(hi, 7.0 - 0.25, 0.05);
}

TEST(BoundaryDots, ThreeCrossingsRoundADotDrawItsCircle) {
  const std::vector<ChangeMark> marks = {DotCrossing(7.0, 10.0, 0, 20.0), DotCrossing(7.0, 130.0, 1, -30.0),
                                         DotCrossing(7.0, 250.0, 2, 40.0)};
  ExpectTheCircleOfRadius7(marks);
  int dots = -1;
  BoundaryLinkOptions off;
  off.max_dot_radius_mm = 0.0;
  EXPECT_TRUE(Dots(marks, DotData(marks, 7.0), &dots, off).empty());
  EXPECT_EQ(dots, 0);
}

// Data every 1 mm of a drag that passed the dot of radius 7 outside it,
// `distance` mm from its centre at its nearest, there at polar angle
// `phi_deg` (region kOutside all along).
std::vector<LabelledPoint> PassingDrag(double distance, double phi_deg) {
  const double phi = phi_deg * std::numbers::pi / 180.0;
  const Eigen::Vector3d nearest{distance * std::cos(phi), distance * std::sin(phi), 0.0};
  const Eigen::Vector3d along{-std::sin(phi), std::cos(phi), 0.0};
  std::vector<LabelledPoint> data;
  for (double t = -8.0; t <= 8.0; t += 1.0) data.push_back({nearest + t * along, kOutside});
  return data;
}

// Crossings on 100 degrees of the circle (a gap of 260) draw it when a drag
// that passed it outside, on the far side, closes the gap (its data just
// outside the circle span 209-271 degrees: the widest gap is then 109).
// Their own drags' data alone do not: the gap could face the inside of a
// larger region (BoundaryDots.TwoCrossingsOfEachSideNearAPatchsCornerAreNoDot).
TEST(BoundaryDots, CrossingsOnAQuarterOfTheCircleDrawItWhenDataOfTheOutsideCloseTheRest) {
  const std::vector<ChangeMark> marks = {DotCrossing(7.0, 0.0, 0), DotCrossing(7.0, 50.0, 1),
                                         DotCrossing(7.0, 100.0, 2)};
  int dots = -1;
  EXPECT_TRUE(Dots(marks, DotData(marks, 7.0), &dots).empty());
  EXPECT_EQ(dots, 0) << "nothing closes the gap";
  std::vector<LabelledPoint> data = DotData(marks, 7.0);
  const std::vector<LabelledPoint> passing = PassingDrag(9.0, 240.0);
  data.insert(data.end(), passing.begin(), passing.end());
  const std::vector<LabelledPoint> points = Dots(marks, data, &dots);
  EXPECT_EQ(dots, 1);
  const auto [lo, hi] = InnerSeedRadii(points);
  EXPECT_NEAR(lo, 7.0 - 0.25, 0.05);
  EXPECT_NEAR(hi, 7.0 - 0.25, 0.05);
  BoundaryLinkOptions before;
  before.min_dot_arc_deg = 180.0;
  EXPECT_TRUE(Dots(marks, data, &dots, before).empty());
  EXPECT_EQ(dots, 0) << "the build before: the crossings must surround the centre";
  // The passing drag closes the gap only from within dot_ring_radii.
  data = DotData(marks, 7.0);
  const std::vector<LabelledPoint> far = PassingDrag(11.0, 240.0);
  data.insert(data.end(), far.begin(), far.end());
  EXPECT_TRUE(Dots(marks, data, &dots).empty());
  EXPECT_EQ(dots, 0);
}

// Two crossings of each side of a square patch (x < 0, y < 0), 5 and 15 mm
// from its corner, lie exactly on a circle of 11.2 mm about (-10, -10), on
// an arc of 143 degrees, and their drags' data (16 mm into either region)
// agree with a dot as with a corner. No other region's data lie beyond the
// gap: that is the patch's inside. So no dot (BoundaryCorners draws the
// corner).
TEST(BoundaryDots, TwoCrossingsOfEachSideNearAPatchsCornerAreNoDot) {
  const testing::PatchScene scene = testing::PatchCorner(5.0, 16.0);  // the patch is region 1, as kDot
  int dots = -1;
  EXPECT_TRUE(Dots(scene.marks, scene.data, &dots).empty());
  EXPECT_EQ(dots, 0);
}

TEST(BoundaryDots, CrossingsOnOneSideOnlyDrawNothing) {
  // 0-70 degrees: a gap of 290 degrees, the far side a guess, even where
  // drags that passed the far side close the gap (min_dot_arc_deg 90).
  const std::vector<ChangeMark> marks = {DotCrossing(7.0, 0.0, 0), DotCrossing(7.0, 35.0, 1),
                                         DotCrossing(7.0, 70.0, 2)};
  std::vector<LabelledPoint> data = DotData(marks, 7.0);
  for (double phi : {150.0, 240.0, 300.0}) {
    const std::vector<LabelledPoint> passing = PassingDrag(9.0, phi);
    data.insert(data.end(), passing.begin(), passing.end());
  }
  int dots = -1;
  EXPECT_TRUE(Dots(marks, data, &dots).empty());
  EXPECT_EQ(dots, 0);
}

TEST(BoundaryDots, AStraightBoundaryOrARegionLargerThanADragIsNoDot) {
  // Three crossings of the straight line x = 0 (region 1 at x > 0).
  std::vector<ChangeMark> line;
  for (int k = 0; k < 3; ++k) {
    ChangeMark m;
    m.position = {0.0, 10.0 * k, 0.0};
    m.direction = Eigen::Vector3d::UnitX();
    m.before = kOutside;
    m.after = kDot;
    m.drag = k;
    line.push_back(m);
  }
  int dots = 0;
  Dots(line, {}, &dots);
  EXPECT_EQ(dots, 0);
  // A round region of radius 20 mm: larger than max_dot_radius_mm.
  const std::vector<ChangeMark> big = {DotCrossing(20.0, 0.0, 0), DotCrossing(20.0, 120.0, 1),
                                       DotCrossing(20.0, 240.0, 2)};
  Dots(big, DotData(big, 20.0), &dots);
  EXPECT_EQ(dots, 0);
}

TEST(BoundaryDots, MarksOffTheCircleOrGrazingDragsDrawNothing) {
  int dots = 0;
  // A 14 mm square patch: three sides crossed in their middles, one corner.
  const std::vector<ChangeMark> square = {DotCrossing(7.0, 0.0, 0), DotCrossing(7.0, 90.0, 1),
                                          DotCrossing(7.0, 180.0, 2), DotCrossing(7.0 * std::sqrt(2.0), 225.0, 3)};
  Dots(square, {}, &dots);
  EXPECT_EQ(dots, 0);
  // A drag running 80 degrees off the radius grazes the edge: two steep
  // crossings are too few.
  const std::vector<ChangeMark> grazing = {DotCrossing(7.0, 0.0, 0), DotCrossing(7.0, 120.0, 1, 80.0),
                                           DotCrossing(7.0, 240.0, 2)};
  Dots(grazing, {}, &dots);
  EXPECT_EQ(dots, 0);
}

TEST(BoundaryDots, AGrazingCrossingOnTheCircleClosesItsGap) {
  // Three steep crossings within 70 degrees (a gap of 290 degrees: too few
  // alone), and a drag that grazed the edge 80 degrees off the radius in the
  // gap, on the circle (held_block seed 3: the grazing crossing closed a
  // 183-degree gap, when the marks had to surround the centre).
  const std::vector<ChangeMark> marks = {DotCrossing(7.0, 0.0, 0), DotCrossing(7.0, 35.0, 1),
                                         DotCrossing(7.0, 70.0, 2), DotCrossing(7.0, 200.0, 3, 80.0)};
  ExpectTheCircleOfRadius7(marks);
  int dots = -1;
  BoundaryLinkOptions before;
  before.dot_grazing_crossings_on_circle = false;
  Dots(marks, DotData(marks, 7.0), &dots, before);
  EXPECT_EQ(dots, 0) << "the build before: the grazing drag refuses the dot";
}

TEST(BoundaryDots, DataAgainstTheCircleStopsIt) {
  const std::vector<ChangeMark> marks = {DotCrossing(7.0, 10.0, 0), DotCrossing(7.0, 130.0, 1),
                                         DotCrossing(7.0, 250.0, 2)};
  int dots = 0;
  // The outer region found inside the circle (a drag through the middle
  // that saw no dot: it is a ring, or not round).
  std::vector<LabelledPoint> data = DotData(marks, 7.0);
  data.push_back({{1.0, -1.0, 0.0}, kOutside});
  Dots(marks, data, &dots);
  EXPECT_EQ(dots, 0);
  // The dot's region found 3 mm outside it: it is larger, or not round.
  data = DotData(marks, 7.0);
  data.push_back({{0.0, -10.0, 0.0}, kDot});
  Dots(marks, data, &dots);
  EXPECT_EQ(dots, 0);
  // A third region in the ring is no contradiction; inside it is.
  data = DotData(marks, 7.0);
  data.push_back({{0.0, -9.5, 0.0}, 2});
  Dots(marks, data, &dots);
  EXPECT_EQ(dots, 1);
  data.push_back({{0.0, -2.0, 0.0}, 2});
  Dots(marks, data, &dots);
  EXPECT_EQ(dots, 0);
}

// The point of the plate at distance r from the dot's centre, polar angle
// phi_deg.
Eigen::Vector3d AtPolar(double r, double phi_deg) {
  const double phi = phi_deg * std::numbers::pi / 180.0;
  return {r * std::cos(phi), r * std::sin(phi), 0.0};
}

TEST(BoundaryDots, DataOffTheCircleByACrossingsOwnErrorDoesNotStopIt) {
  const std::vector<ChangeMark> marks = {DotCrossing(7.0, 10.0, 0), DotCrossing(7.0, 130.0, 1),
                                         DotCrossing(7.0, 250.0, 2)};
  // Drags whose changes were located 0.4 mm off the true edge, as far as a
  // crossing of the dot may lie off its circle (max_dot_residual_mm): the
  // dot's data 0.4 mm outside it, the outer region's 0.4 mm inside.
  const BoundaryLinkOptions defaults;
  ASSERT_GT(defaults.max_dot_residual_mm, 0.4);
  int dots = 0;
  std::vector<LabelledPoint> data = DotData(marks, 7.0);
  data.push_back({AtPolar(7.4, 70.0), kDot});
  data.push_back({AtPolar(6.6, 190.0), kOutside});
  Dots(marks, data, &dots);
  EXPECT_EQ(dots, 1);
  // Checked as a link is (seed_offset_mm, 0.25 mm), each refuses the dot
  // (any contradicted chord refusing the whole circle, as in that build).
  BoundaryLinkOptions as_a_link;
  as_a_link.max_dot_data_offset_mm = as_a_link.seed_offset_mm;
  as_a_link.max_dot_contradicted_chord_share = 0.0;
  Dots(marks, data, &dots, as_a_link);
  EXPECT_EQ(dots, 0);
  data.pop_back();
  Dots(marks, data, &dots, as_a_link);
  EXPECT_EQ(dots, 0);
  // 0.7 mm off is more than a crossing's error: it contradicts the chords
  // beside it (and with no share of chords left out, the whole circle).
  data = DotData(marks, 7.0);
  data.push_back({AtPolar(7.7, 70.0), kDot});
  BoundaryLinkOptions whole_circle;
  whole_circle.max_dot_contradicted_chord_share = 0.0;
  Dots(marks, data, &dots, whole_circle);
  EXPECT_EQ(dots, 0);
}

// The chords of the dot of radius 7 drawn (their middles' polar angles,
// degrees in [0, 360)).
std::vector<double> ChordAngles(const std::vector<ChangeMark>& marks, const std::vector<LabelledPoint>& data,
                                const BoundaryLinkOptions& o = {}) {
  std::vector<double> angles;
  for (const BoundaryDot& dot : FindDots(marks, LabelledPointGrid(data, 5.0), o)) {
    for (const BoundarySegment& chord : dot.chords) {
      const Eigen::Vector3d mid = 0.5 * (chord.p + chord.q);
      double deg = std::atan2(mid.y(), mid.x()) * 180.0 / std::numbers::pi;
      angles.push_back(deg < 0.0 ? deg + 360.0 : deg);
    }
  }
  return angles;
}

TEST(BoundaryDots, ChordsDataContradictAreLeftOutAndTheRestOfTheCircleDrawn) {
  const std::vector<ChangeMark> marks = {DotCrossing(7.0, 10.0, 0), DotCrossing(7.0, 130.0, 1),
                                         DotCrossing(7.0, 250.0, 2)};
  // A drag that grazed the rim blended its last piece across the edge: the
  // dot's label 0.8 mm outside the circle at 70 degrees (held_block seed 2,
  // docs/method.md).
  std::vector<LabelledPoint> data = DotData(marks, 7.0);
  data.push_back({AtPolar(7.8, 70.0), kDot});
  const int all = static_cast<int>(ChordAngles(marks, DotData(marks, 7.0)).size());
  ASSERT_EQ(all, 44);  // 1 mm chords round 7 mm
  const std::vector<double> kept = ChordAngles(marks, data);
  EXPECT_GE(static_cast<int>(kept.size()), all - 3);
  EXPECT_LT(static_cast<int>(kept.size()), all);
  for (double deg : kept) EXPECT_GT(std::abs(deg - 70.0), 5.0) << "a chord beside the contradicting point";
  BoundaryLinkOptions before;
  before.max_dot_contradicted_chord_share = 0.0;
  EXPECT_TRUE(ChordAngles(marks, data, before).empty()) << "the build before refuses the whole circle";
  // The dot's label outside the circle all along a quarter of it: the dot
  // is larger there, not round, and more than an eighth of its chords are
  // contradicted.
  for (double deg = 20.0; deg <= 110.0; deg += 4.0) data.push_back({AtPolar(7.8, deg), kDot});
  EXPECT_TRUE(ChordAngles(marks, data).empty());
}

TEST(BoundaryDots, TheCircleReplacesTheChordLinkedBetweenTwoOfItsCrossings) {
  // Crossings 50 degrees apart, each drag on the radius: both within 25
  // degrees of perpendicular to their chord, so a link joins them.
  const std::vector<ChangeMark> marks = {DotCrossing(7.0, 0.0, 0), DotCrossing(7.0, 50.0, 1),
                                         DotCrossing(7.0, 200.0, 2)};
  const std::vector<LabelledPoint> data = DotData(marks, 7.0);
  BoundaryLinkOptions no_dots;
  no_dots.max_dot_radius_mm = 0.0;
  int links = 0, dots = -1;
  const std::vector<LabelledPoint> chord = BoundaryLinkPoints(marks, data, no_dots, &links, nullptr, nullptr, &dots);
  EXPECT_EQ(links, 1);
  EXPECT_EQ(dots, 0);
  // The chord's inner seeds lie 7 cos 25 - 0.25 = 6.1 mm from the centre.
  EXPECT_LT(InnerSeedRadii(chord).first, 6.2);
  const std::vector<LabelledPoint> circle = BoundaryLinkPoints(marks, data, {}, &links, nullptr, nullptr, &dots);
  EXPECT_EQ(links, 0);
  EXPECT_EQ(dots, 1) << "counted for the map's report";
  const auto [lo, hi] = InnerSeedRadii(circle);
  EXPECT_NEAR(lo, 7.0 - 0.25, 0.05);
  EXPECT_NEAR(hi, 7.0 - 0.25, 0.05);
}

// Crossings of a dot of radius 7 every 360/n degrees from 15, the one at
// 135 located `outlier_inside` mm inside the circle: its drag's data read
// the outside up to where its change was located (held_block service seed
// 4, docs/method.md).
struct OutlierDot {
  std::vector<ChangeMark> marks;
  std::vector<LabelledPoint> data;
};
OutlierDot DotWithOneCrossingOff(int n, double outlier_inside) {
  OutlierDot dot;
  for (int k = 0; k < n; ++k) {
    const double deg = 15.0 + 360.0 * k / n;
    dot.marks.push_back(DotCrossing(std::abs(deg - 135.0) < 1e-9 ? 7.0 - outlier_inside : 7.0, deg, k));
  }
  for (const ChangeMark& m : dot.marks) {  // DotData's, read by where each change was located
    const double located = m.position.norm();
    for (double t = -8.0; t <= 8.0; t += 1.0) {
      const Eigen::Vector3d p = m.position + t * m.direction;
      if (std::abs(p.norm() - located) < 0.3) continue;
      dot.data.push_back({p, p.norm() < located ? kDot : kOutside});
    }
  }
  return dot;
}

TEST(BoundaryDots, OneCrossingLocatedOffTheCircleIsExcusedAmongSix) {
  const OutlierDot dot = DotWithOneCrossingOff(6, 1.2);
  int dots = -1;
  const std::vector<LabelledPoint> points = Dots(dot.marks, dot.data, &dots);
  EXPECT_EQ(dots, 1);
  const auto [lo, hi] = InnerSeedRadii(points);
  EXPECT_NEAR(lo, 7.0 - 0.25, 0.05) << "the circle through the other five";
  EXPECT_NEAR(hi, 7.0 - 0.25, 0.05);
  BoundaryLinkOptions before;
  before.max_dot_outlier_mm = 0.0;
  Dots(dot.marks, dot.data, &dots, before);
  EXPECT_EQ(dots, 0) << "the build before refuses the circle";
  BoundaryLinkOptions seven;
  seven.min_dot_crossings_to_excuse_one = 7;
  Dots(dot.marks, dot.data, &dots, seven);
  EXPECT_EQ(dots, 0) << "six crossings, seven needed to excuse one";
  const OutlierDot far_off = DotWithOneCrossingOff(6, 2.0);
  Dots(far_off.marks, far_off.data, &dots);
  EXPECT_EQ(dots, 0) << "2 mm off: not a located change's error";
}

TEST(BoundaryDots, OptionsRefuseARingInsideTheDotAnArcBeyondAHalfCircleAndBadOutlierRulesByName) {
  for (double ring : {0.5, -1.0, std::nan("")}) {
    BoundaryLinkOptions options;
    options.dot_ring_radii = ring;
    std::string why;
    EXPECT_FALSE(options.IsValid(&why)) << ring;
    EXPECT_NE(why.find("dot_ring_radii"), std::string::npos) << why;
  }
  BoundaryLinkOptions options;
  options.min_dot_arc_deg = 200.0;
  std::string why;
  EXPECT_FALSE(options.IsValid(&why));
  EXPECT_NE(why.find("min_dot_arc_deg"), std::string::npos) << why;
  options = {};
  options.max_dot_contradicted_chord_share = 1.5;
  EXPECT_FALSE(options.IsValid(&why));
  EXPECT_NE(why.find("max_dot_contradicted_chord_share"), std::string::npos) << why;
  options = {};
  options.min_dot_crossings_to_excuse_one = 4;
  EXPECT_FALSE(options.IsValid(&why));
  EXPECT_NE(why.find("min_dot_crossings_to_excuse_one"), std::string::npos) << why;
  options = {};
  options.max_dot_outlier_mm = -1.0;
  EXPECT_FALSE(options.IsValid(&why));
  EXPECT_NE(why.find("max_dot_outlier_mm"), std::string::npos) << why;
}

}  // namespace
}  // namespace surfmap
