#include "server/map/boundary_bridges.h"

#include <limits>
#include <vector>

#include <gtest/gtest.h>
#include "server/map/boundary_links.h"
#include "server/map/testing/boundary_crossings.h"

namespace surfmap {
namespace {

using testing::Crossing;
using testing::DragData;

// A strip's edge, the line x = 0: the strip (region 0) at x < 0. Beyond the
// edge lies wood (region 1), except where a patch of masonite (region 2)
// meets it, for |y| < 20. Drags crossed the edge outside the patch only: at
// y = -40, -30 and 30, 40, each pair linked, so the two chains end 60 mm
// apart and point at each other.
struct StripThroughPatch {
  std::vector<ChangeMark> marks = {Crossing(-40.0, 0), Crossing(-30.0, 1), Crossing(30.0, 2), Crossing(40.0, 3)};
  std::vector<DrawnLink> links = {{0, 1, 0, 1, -Eigen::Vector3d::UnitX()}, {2, 3, 0, 1, -Eigen::Vector3d::UnitX()}};
  std::vector<LabelledPoint> data;
  BoundaryLinkOptions options;

  StripThroughPatch() {
    data = DragData(marks);
    // Drags inside the patch, 6 mm off the strip's edge, saw only masonite;
    // one ran along the strip, 3.5 mm inside it.
    for (double y = -18.0; y <= 18.0; y += 2.0) {
      data.push_back({{6.0, y, 0.0}, 2});
      data.push_back({{-3.5, y, 0.0}, 0});
    }
    options.max_bridge_mm = 65.0;
  }

  std::vector<LabelledPoint> Bridge(int* bridges) const {
    return BoundaryBridgePoints(marks, links, LabelledPointGrid(data, 5.0), options, bridges);
  }
};

// The label of the point nearest `at` among `points`; -1 when there are none.
int LabelNearest(const std::vector<LabelledPoint>& points, const Eigen::Vector3d& at) {
  int label = -1;
  double best = std::numeric_limits<double>::infinity();
  for (const LabelledPoint& p : points) {
    if (const double d = (p.point - at).norm(); d < best) best = d, label = p.label;
  }
  return label;
}

TEST(BoundaryBridges, AStripsEdgeIsCarriedThroughAPatchAgainstThePatchsRegion) {
  const StripThroughPatch scene;
  int bridges = 0;
  const std::vector<LabelledPoint> points = scene.Bridge(&bridges);
  EXPECT_EQ(bridges, 1);
  // The strip's side all along; beyond the edge, the region the data there
  // shows: wood next to the chains' ends, masonite along the patch.
  for (double y : {-25.0, -10.0, 0.0, 10.0, 25.0}) EXPECT_EQ(LabelNearest(points, {-0.25, y, 0.0}), 0) << y;
  for (double y : {-10.0, 0.0, 10.0}) EXPECT_EQ(LabelNearest(points, {0.25, y, 0.0}), 2) << y;
  for (double y : {-27.0, 27.0}) EXPECT_EQ(LabelNearest(points, {0.25, y, 0.0}), 1) << y;
  // Nothing is drawn past the chains' ends: the links draw those.
  for (const LabelledPoint& p : points) EXPECT_LE(std::abs(p.point.y()), 30.0 + 1e-9);
}

TEST(BoundaryBridges, DataAcrossTheChordBeyondItsToleranceStopsTheBridge) {
  StripThroughPatch scene;
  const double tolerance = scene.options.bridge_tolerance_mm;
  int bridges = 0;
  // Masonite within the tolerance on the strip's side of the chord: what
  // the chord (known from its ends) and a piece's end leave uncertain.
  scene.data.push_back({{-0.8 * tolerance, 5.0, 0.0}, 2});
  scene.Bridge(&bridges);
  EXPECT_EQ(bridges, 1);
  // Beyond it, into the strip: a drag found masonite where the strip should be.
  scene.data.push_back({{-1.5 * tolerance, 5.0, 0.0}, 2});
  scene.Bridge(&bridges);
  EXPECT_EQ(bridges, 0);
  // The strip beyond it in the patch: as much a contradiction.
  scene.data.pop_back();
  scene.data.push_back({{1.5 * tolerance, -5.0, 0.0}, 0});
  scene.Bridge(&bridges);
  EXPECT_EQ(bridges, 0);
  // A fourth region (neither side's) within the corridor.
  scene.data.pop_back();
  scene.data.push_back({{-0.5, 0.0, 0.0}, 3});
  scene.Bridge(&bridges);
  EXPECT_EQ(bridges, 0);
}

TEST(BoundaryBridges, ChainsThatDoNotPointAtEachOtherAreNotBridged) {
  // The upper chain turns away: its second crossing lies 5 mm off the line,
  // so the chain leaves its end 27 degrees off the chord to the lower one.
  StripThroughPatch scene;
  scene.marks[3].position.x() = 5.0;
  int bridges = 0;
  scene.Bridge(&bridges);
  EXPECT_EQ(bridges, 0);
  // 1.5 mm off: 8.5 degrees, within a line's turn (10 degrees).
  scene.marks[3].position.x() = 1.5;
  scene.Bridge(&bridges);
  EXPECT_EQ(bridges, 1);
}

TEST(BoundaryBridges, AGapWithTheSameRegionBeyondItIsLeftToExtensions) {
  StripThroughPatch scene;
  for (LabelledPoint& p : scene.data) {
    if (p.label == 2) p.label = 1;  // no patch: wood all along
  }
  int bridges = 0;
  EXPECT_TRUE(scene.Bridge(&bridges).empty());
  EXPECT_EQ(bridges, 0);
}

TEST(BoundaryBridges, AThirdRegionShorterThanALinkBeyondTheChordIsNoBridge) {
  // Wood measured 9 mm off the edge all along, masonite 6 mm off it only for
  // |y| <= 3: the masonite is nearest the chord for about 19 mm, shorter
  // than a link, as the data beyond a narrow neighbour would be.
  StripThroughPatch scene;
  std::erase_if(scene.data, [](const LabelledPoint& p) { return p.label == 2 && std::abs(p.point.y()) > 3.0; });
  for (double y = -28.0; y <= 28.0; y += 2.0) scene.data.push_back({{9.0, y, 0.0}, 1});
  int bridges = 0;
  EXPECT_TRUE(scene.Bridge(&bridges).empty());
  EXPECT_EQ(bridges, 0);
  // With a link's length of 10 mm it is long enough.
  scene.options.max_length_mm = 10.0;
  scene.Bridge(&bridges);
  EXPECT_EQ(bridges, 1);
}

TEST(BoundaryBridges, ABridgeIsNoLongerThanItsLimit) {
  StripThroughPatch scene;
  int bridges = 0;
  scene.options.max_bridge_mm = 55.0;  // the ends are 60 mm apart
  scene.Bridge(&bridges);
  EXPECT_EQ(bridges, 0);
  scene.options.max_bridge_mm = 0.0;  // off
  EXPECT_TRUE(scene.Bridge(&bridges).empty());
  EXPECT_EQ(bridges, 0);
}

TEST(BoundaryBridges, TheLinksDrawTheBridgeWithTheirOwnChains) {
  // Through BoundaryLinkPoints: the two pairs of crossings are linked, and
  // the bridge adds the patch's stretch between them.
  const StripThroughPatch scene;
  BoundaryLinkOptions off = scene.options;
  off.max_bridge_mm = 0.0;
  int links = 0;
  const std::vector<LabelledPoint> without = BoundaryLinkPoints(scene.marks, scene.data, off, &links);
  EXPECT_EQ(links, 2);
  EXPECT_EQ(LabelNearest(without, {0.25, 0.0, 0.0}), 1);  // the nearest link point is a chain's, 30 mm away
  const std::vector<LabelledPoint> with = BoundaryLinkPoints(scene.marks, scene.data, scene.options, &links);
  EXPECT_EQ(links, 2);
  EXPECT_EQ(LabelNearest(with, {0.25, 0.0, 0.0}), 2);
  EXPECT_EQ(LabelNearest(with, {-0.25, 0.0, 0.0}), 0);
}

TEST(BoundaryBridges, OptionsRefuseANegativeLimitByName) {
  for (const char* name : {"max_bridge_mm", "bridge_tolerance_mm"}) {
    BoundaryLinkOptions options;
    (std::string(name) == "max_bridge_mm" ? options.max_bridge_mm : options.bridge_tolerance_mm) = -1.0;
    std::string why;
    EXPECT_FALSE(options.IsValid(&why)) << name;
    EXPECT_NE(why.find(name), std::string::npos) << why;
  }
}

}  // namespace
}  // namespace surfmap
