#include "server/map/boundary_corners.h"

#include <cmath>

#include <gtest/gtest.h>

#include "server/map/boundary_links.h"

namespace surfmap {
namespace {

// A square patch (region 1) in the quadrant x < 0, y < 0 of the plate z = 0,
// region 0 around it. Its side x = 0 is crossed by drags along +x, its side
// y = 0 by drags along +y; the corner at the origin by none.
int Truth(const Eigen::Vector3d& p) { return p.x() < 0.0 && p.y() < 0.0 ? 1 : 0; }

ChangeMark Mark(const Eigen::Vector3d& at, const Eigen::Vector3d& direction, int drag) {
  ChangeMark m;
  m.position = at;
  m.direction = direction;
  m.normal = Eigen::Vector3d::UnitZ();
  m.before = Truth(at - 0.5 * direction);
  m.after = Truth(at + 0.5 * direction);
  m.drag = drag;
  return m;
}

struct Scene {
  std::vector<ChangeMark> marks;
  std::vector<LabelledPoint> data;
  void Drag(const Eigen::Vector3d& crossing, const Eigen::Vector3d& direction) {
    marks.push_back(Mark(crossing, direction, static_cast<int>(marks.size())));
    for (double s = -8.0; s <= 8.0; s += 0.5) {
      if (s == 0.0) continue;
      const Eigen::Vector3d p = crossing + s * direction;
      data.push_back({p, Truth(p)});
    }
  }
};

// Two crossings of each side, `near` mm from the corner and 10 mm farther.
Scene PatchCorner(double near) {
  Scene scene;
  scene.Drag({0.0, -near, 0.0}, Eigen::Vector3d::UnitX());
  scene.Drag({0.0, -near - 10.0, 0.0}, Eigen::Vector3d::UnitX());
  scene.Drag({-near, 0.0, 0.0}, Eigen::Vector3d::UnitY());
  scene.Drag({-near - 10.0, 0.0, 0.0}, Eigen::Vector3d::UnitY());
  return scene;
}

TEST(BoundaryCorners, TheLastCrossingsOfTwoSidesAreJoinedThroughTheCornerOnTheirOwnSides) {
  const Scene scene = PatchCorner(5.0);
  int links = 0, corners = 0;
  const std::vector<LabelledPoint> points = BoundaryLinkPoints(scene.marks, scene.data, {}, &links, &corners);
  EXPECT_EQ(links, 2);
  EXPECT_EQ(corners, 1);
  const BoundaryLinkOptions o;
  int near_corner = 0;
  for (const LabelledPoint& p : points) {
    // At the corner itself the points lie on the sides' lines: their side is
    // a matter of rounding.
    if (p.point.head<2>().norm() < 1.0) ++near_corner;
    if (p.point.head<2>().norm() <= o.seed_offset_mm + 1e-9) continue;
    // Every other point lies seed_offset_mm off the patch's true sides, on
    // its own region's side (1e-9: rounding).
    const double to_side = std::min(std::abs(p.point.x()) + std::max(0.0, p.point.y()),
                                    std::abs(p.point.y()) + std::max(0.0, p.point.x()));
    EXPECT_NEAR(to_side, o.seed_offset_mm, 1e-9) << p.point.transpose();
    EXPECT_EQ(p.label, Truth(p.point)) << p.point.transpose();
  }
  EXPECT_GT(near_corner, 0) << "the corner itself carries points";
}

TEST(BoundaryCorners, DataOfTheOtherRegionInsideTheCornerVetoesIt) {
  Scene scene = PatchCorner(5.0);
  scene.data.push_back({{-1.5, -1.5, 0.0}, 0});  // the patch's corner is cut off after all
  int corners = -1;
  BoundaryLinkPoints(scene.marks, scene.data, {}, nullptr, &corners);
  EXPECT_EQ(corners, 0);
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

}  // namespace
}  // namespace surfmap
