#include "server/mesh/mesh_locator.h"

#include <gtest/gtest.h>
#include "server/mesh/primitive_meshes.h"

namespace surfmap {
namespace {

TEST(MeshLocatorTest, FindsTheClosestPointOnAnyLevel) {
  auto control = MakeIcosphere(10.0, 1);
  ASSERT_TRUE(control.ok());
  auto surface = LoopSurface::Create(*control, 2);
  ASSERT_TRUE(surface.ok());
  // Level 1 is not the surface's finest: the locator searches its own mesh.
  MeshLocator locator((*surface)->level(1));
  const SurfacePoint hit = locator.Closest(Eigen::Vector3d(0, 0, 30));
  ASSERT_GE(hit.triangle, 0);
  const auto& t = (*surface)->level(1).triangles[hit.triangle];
  const auto& p = (*surface)->level(1).limit_positions;
  const Eigen::Vector3d rebuilt = hit.barycentric[0] * p[t[0]] + hit.barycentric[1] * p[t[1]] + hit.barycentric[2] * p[t[2]];
  EXPECT_NEAR((rebuilt - hit.position).norm(), 0.0, 1e-9);
  EXPECT_NEAR(hit.distance, (hit.position - Eigen::Vector3d(0, 0, 30)).norm(), 1e-9);
  EXPECT_GT(hit.normal.z(), 0.9);  // outward at the top
  // Moving the locator keeps it working (its tree points into its own copy).
  MeshLocator moved = std::move(locator);
  EXPECT_EQ(moved.Closest(Eigen::Vector3d(0, 0, 30)).triangle, hit.triangle);
}

TEST(MeshLocatorTest, ClosestAlongALineFindsWhereItMeetsTheSurface) {
  auto control = MakeIcosphere(15.0, 3);
  ASSERT_TRUE(control.ok());
  auto surface = LoopSurface::Create(*control, 1);
  ASSERT_TRUE(surface.ok());
  const MeshLocator locator((*surface)->level(1));
  // A point of the plane tangent at the top, 12 mm out: the nearest surface
  // point lies towards the centre, the one along the plane's normal below it.
  const Eigen::Vector3d in_plane(12.0, 0.0, 15.0), down(0.0, 0.0, -1.0);
  const SurfacePoint nearest = locator.Closest(in_plane);
  const SurfacePoint along = locator.ClosestAlong(in_plane, down);
  ASSERT_GE(along.triangle, 0);
  EXPECT_NEAR(along.position.x(), 12.0, 0.05);
  EXPECT_NEAR(along.position.y(), 0.0, 0.05);
  EXPECT_NEAR(along.position.norm(), 15.0, 0.2);  // the mesh's facets lie inside the sphere
  EXPECT_LT(nearest.position.x(), 10.5);           // 15 * 12 / 19.2 = 9.4
  // A line that passes beside the object meets nothing.
  EXPECT_EQ(locator.ClosestAlong(Eigen::Vector3d(20.0, 0.0, 15.0), down).triangle, -1);
}

TEST(MeshLocatorTest, AnEmptyMeshFindsNothing) {
  const MeshLocator locator({}, {});
  EXPECT_EQ(locator.Closest(Eigen::Vector3d::Zero()).triangle, -1);
  EXPECT_EQ(locator.ClosestAlong(Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ()).triangle, -1);
}

}  // namespace
}  // namespace surfmap
