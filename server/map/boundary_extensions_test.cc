#include "server/map/boundary_extensions.h"

#include <gtest/gtest.h>
#include "server/map/boundary_links.h"
#include "server/map/testing/boundary_crossings.h"

namespace surfmap {
namespace {

using testing::Crossing;
using testing::DragData;
using testing::LinksDrawn;

TEST(BoundaryExtensions, AChainIsCarriedOnThroughObliqueCrossingsOfItsBoundary) {
  // Two drags across the boundary make a link; drags 50 and 60 degrees off
  // perpendicular, farther along it, are too oblique for a link of their own.
  const std::vector<ChangeMark> marks = {Crossing(0.0, 0), Crossing(10.0, 1), Crossing(20.0, 2, 50.0),
                                         Crossing(32.0, 3, -60.0)};
  BoundaryLinkOptions off;
  off.max_extension_turn_deg = 0.0;
  off.max_line_turn_deg = 0.0;  // the three oblique crossings would make a line of their own (boundary_lines.h)
  EXPECT_EQ(LinksDrawn(marks, off), 1);
  EXPECT_EQ(LinksDrawn(marks), 3);  // carried on twice: 10 -> 20 -> 32

  const std::vector<ChangeMark> both_ends = {Crossing(-12.0, 4, 55.0), Crossing(0.0, 0), Crossing(10.0, 1),
                                             Crossing(20.0, 2, 50.0)};
  EXPECT_EQ(LinksDrawn(both_ends), 3);
}

TEST(BoundaryExtensions, AChainIsCarriedOnFartherThanALinkReaches) {
  // An oblique crossing 26 mm past the chain's end, on its line: beyond a
  // link's 20 mm, within an extension's 30.
  const std::vector<ChangeMark> marks = {Crossing(0.0, 0), Crossing(10.0, 1), Crossing(36.0, 2, 50.0)};
  EXPECT_EQ(LinksDrawn(marks), 2);
  BoundaryLinkOptions as_a_link;
  as_a_link.max_extension_length_mm = as_a_link.max_length_mm;
  EXPECT_EQ(LinksDrawn(marks, as_a_link), 1);
  // Perpendicular crossings 26 mm apart with no chain are not linked.
  EXPECT_EQ(LinksDrawn({Crossing(0.0, 0), Crossing(26.0, 1)}), 0);
}

TEST(BoundaryExtensions, APatchCornerIsNotCutAcross) {
  // The boundary turns by 90 degrees at (0, 14) and runs on along y = 14;
  // a drag along -y crosses that side at (6, 14). The chord from the
  // chain's end at (0, 10) turns 56 degrees from the chain: a corner's.
  std::vector<ChangeMark> marks = {Crossing(0.0, 0), Crossing(10.0, 1)};
  ChangeMark side;
  side.position = {6.0, 14.0, 0.0};
  side.direction = {0.0, -1.0, 0.0};  // from region 0 above that side into the patch, region 1
  side.normal = Eigen::Vector3d::UnitZ();
  side.before = 0;
  side.after = 1;
  side.drag = 2;
  marks.push_back(side);
  EXPECT_EQ(LinksDrawn(marks), 1);
  // The sides agree and the drag crosses the chord: only the turn tells.
  BoundaryLinkOptions any_turn;
  any_turn.max_extension_turn_deg = 90.0;
  EXPECT_EQ(LinksDrawn(marks, any_turn), 2);
}

TEST(BoundaryExtensions, DragsThatGrazeTheBoundaryOrDataAgainstItStopTheChain) {
  // 85 degrees off perpendicular: along the boundary more than across it
  // (past both the extensions' 75 and a line's 80).
  EXPECT_EQ(LinksDrawn({Crossing(0.0, 0), Crossing(10.0, 1), Crossing(20.0, 2, 85.0)}), 1);

  const std::vector<ChangeMark> marks = {Crossing(0.0, 0), Crossing(10.0, 1), Crossing(20.0, 2, 50.0)};
  std::vector<LabelledPoint> data = DragData(marks);
  data.push_back({{-0.8, 15.0, 0.0}, 1});  // region 1 found 0.8 mm on region 0's side
  int links = 0;
  BoundaryLinkPoints(marks, data, {}, &links);
  EXPECT_EQ(links, 1);
}

TEST(BoundaryExtensions, ExtensionsJoinTheCrossingToTheChainEndWithRegionAOnItsSide) {
  const std::vector<ChangeMark> marks = {Crossing(0.0, 0), Crossing(10.0, 1), Crossing(20.0, 2, 50.0)};
  const std::vector<DrawnLink> links = {{0, 1, 0, 1, -Eigen::Vector3d::UnitX()}};
  const LabelledPointGrid grid(DragData(marks), 5.0);
  const std::vector<DrawnLink> out = ExtendChains(marks, links, grid, {});
  ASSERT_EQ(out.size(), 2u);
  EXPECT_EQ(out[1].from, 1);
  EXPECT_EQ(out[1].to, 2);
  EXPECT_EQ(out[1].a, 0);
  EXPECT_EQ(out[1].b, 1);
  EXPECT_NEAR(out[1].towards_a.x(), -1.0, 1e-9);
}

}  // namespace
}  // namespace surfmap
