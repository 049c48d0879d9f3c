#include "server/mesh/primitive_meshes.h"

#include <cmath>
#include <numbers>
#include <set>

#include <gtest/gtest.h>
#include <Eigen/Geometry>
#include "server/mesh/loop_surface.h"
#include "server/mesh/test_data.h"

namespace surfmap {
namespace {

// V - E + F for a triangle mesh.
int EulerCharacteristic(const ControlMesh& mesh) {
  std::set<std::pair<int, int>> edges;
  for (const auto& t : mesh.triangles) {
    for (int i = 0; i < 3; ++i) edges.insert({std::min(t[i], t[(i + 1) % 3]), std::max(t[i], t[(i + 1) % 3])});
  }
  return static_cast<int>(mesh.positions.size()) - static_cast<int>(edges.size()) +
         static_cast<int>(mesh.triangles.size());
}

// Signed volume (divergence theorem): positive iff wound outward.
double SignedVolume(const ControlMesh& mesh) {
  double volume = 0.0;
  for (const auto& t : mesh.triangles) {
    volume += mesh.positions[t[0]].dot(mesh.positions[t[1]].cross(mesh.positions[t[2]])) / 6.0;
  }
  return volume;
}

TEST(PrimitiveMeshesTest, PlatonicSolidsAreValidClosedAndOutward) {
  struct Case {
    ControlMesh mesh;
    std::size_t vertices, faces;
  };
  for (const Case& c : {Case{MakeTetrahedron(2.0), 4, 4}, Case{MakeOctahedron(2.0), 6, 8},
                        Case{MakeIcosahedron(2.0), 12, 20}}) {
    EXPECT_TRUE(ValidateControlMesh(c.mesh).ok()) << ValidateControlMesh(c.mesh);
    EXPECT_EQ(c.mesh.positions.size(), c.vertices);
    EXPECT_EQ(c.mesh.triangles.size(), c.faces);
    EXPECT_EQ(EulerCharacteristic(c.mesh), 2);
    EXPECT_GT(SignedVolume(c.mesh), 0.0);
    for (const Eigen::Vector3d& p : c.mesh.positions) EXPECT_NEAR(p.norm(), 2.0, 1e-12);
  }
}

TEST(PrimitiveMeshesTest, IcosphereCounts) {
  for (int s = 0; s <= 3; ++s) {
    absl::StatusOr<ControlMesh> sphere = MakeIcosphere(10.0, s);
    ASSERT_TRUE(sphere.ok());
    EXPECT_EQ(sphere->triangles.size(), 20u << (2 * s));
    EXPECT_EQ(sphere->positions.size(), 10u * (1u << (2 * s)) + 2);
    EXPECT_TRUE(ValidateControlMesh(*sphere).ok());
    EXPECT_GT(SignedVolume(*sphere), 0.0);
  }
  EXPECT_FALSE(MakeIcosphere(10.0, 7).ok());
  EXPECT_FALSE(MakeIcosphere(-1.0, 1).ok());
}

TEST(PrimitiveMeshesTest, GridPlate) {
  absl::StatusOr<ControlMesh> plate = MakeGridPlate(120.0, 80.0, 6, 4);
  ASSERT_TRUE(plate.ok());
  EXPECT_EQ(plate->positions.size(), 35u);
  EXPECT_EQ(plate->triangles.size(), 48u);
  EXPECT_TRUE(ValidateControlMesh(*plate).ok());
  EXPECT_EQ(EulerCharacteristic(*plate), 1);  // a disc
  for (const auto& t : plate->triangles) {
    const Eigen::Vector3d& a = plate->positions[t[0]];
    EXPECT_GT((plate->positions[t[1]] - a).cross(plate->positions[t[2]] - a).z(), 0.0);
  }
  EXPECT_FALSE(MakeGridPlate(0.0, 1.0, 1, 1).ok());
  EXPECT_FALSE(MakeGridPlate(1.0, 1.0, 0, 1).ok());
}

TEST(PrimitiveMeshesTest, CylinderIsClosed) {
  absl::StatusOr<ControlMesh> cylinder = MakeCylinder(20.0, 50.0, 16, 4);
  ASSERT_TRUE(cylinder.ok());
  EXPECT_EQ(cylinder->triangles.size(), 2u * 16 * 5);
  EXPECT_EQ(cylinder->positions.size(), 16u * 5 + 2);
  EXPECT_TRUE(ValidateControlMesh(*cylinder).ok()) << ValidateControlMesh(*cylinder);
  EXPECT_EQ(EulerCharacteristic(*cylinder), 2);
  // The polygonal cylinder's volume: n/2 r^2 sin(2 pi/n) h.
  EXPECT_NEAR(SignedVolume(*cylinder), 8 * 400.0 * std::sin(2 * std::numbers::pi / 16) * 50.0, 1e-6);
  EXPECT_FALSE(MakeCylinder(20.0, 50.0, 2, 4).ok());
}

TEST(PrimitiveMeshesTest, BottleHasASmoothLoopSurfaceOfTheRightSize) {
  absl::StatusOr<ControlMesh> bottle = MakeBottle();
  ASSERT_TRUE(bottle.ok());
  EXPECT_EQ(bottle->triangles.size(), 360u);
  EXPECT_EQ(bottle->positions.size(), 182u);
  ASSERT_TRUE(ValidateControlMesh(*bottle).ok()) << ValidateControlMesh(*bottle);
  EXPECT_EQ(EulerCharacteristic(*bottle), 2);
  EXPECT_GT(SignedVolume(*bottle), 0.0);

  absl::StatusOr<std::unique_ptr<LoopSurface>> surface = LoopSurface::Create(*bottle, 3);
  ASSERT_TRUE(surface.ok()) << surface.status();
  const SurfaceLevel& finest = (*surface)->finest();
  double z_lo = INFINITY, z_hi = -INFINITY, body_lo = INFINITY, body_hi = 0.0, neck = 0.0;
  for (const Eigen::Vector3d& p : finest.limit_positions) {
    z_lo = std::min(z_lo, p.z());
    z_hi = std::max(z_hi, p.z());
    const double r = std::hypot(p.x(), p.y());
    if (p.z() > 40.0 && p.z() < 110.0) {
      body_lo = std::min(body_lo, r);
      body_hi = std::max(body_hi, r);
    }
    if (p.z() > 180.0 && p.z() < 190.0) neck = std::max(neck, r);
  }
  EXPECT_NEAR(z_lo, 0.0, 2.0);
  EXPECT_NEAR(z_hi, 200.0, 2.0);
  EXPECT_NEAR(body_lo, 40.0, 0.5);
  EXPECT_NEAR(body_hi, 40.0, 0.5);
  EXPECT_NEAR(neck, 14.0, 1.0);
  // Smooth: neighbouring finest normals turn by little, outward everywhere.
  double worst = 1.0;
  for (const auto& e : finest.edges) worst = std::min(worst, finest.limit_normals[e[0]].dot(finest.limit_normals[e[1]]));
  EXPECT_GT(worst, std::cos(25.0 * std::numbers::pi / 180.0));
  for (std::size_t v = 0; v < finest.limit_positions.size(); ++v) {
    const Eigen::Vector3d from_axis = finest.limit_positions[v] - Eigen::Vector3d(0, 0, 100);
    EXPECT_GT(finest.limit_normals[v].dot(from_axis), 0.0) << v;
  }
}

TEST(PrimitiveMeshesTest, BottleDataFileMatchesTheGenerator) {
  absl::StatusOr<ControlMesh> bottle = MakeBottle();
  ASSERT_TRUE(bottle.ok());
  // Not EXPECT_EQ: a mismatch would print two 15 kB files.
  EXPECT_TRUE(ReadMeshTestData("bottle.obj") == WriteObj(*bottle))
      << "regenerate tests/data/meshes/bottle.obj from MakeBottle() (see the README there)";
}

TEST(PrimitiveMeshesTest, PlateDataFileMatchesTheGenerator) {
  absl::StatusOr<ControlMesh> plate = MakeGridPlate(120.0, 80.0, 6, 4);
  ASSERT_TRUE(plate.ok());
  EXPECT_TRUE(ReadMeshTestData("plate.obj") == WriteObj(*plate))
      << "regenerate tests/data/meshes/plate.obj from MakeGridPlate(120, 80, 6, 4) (see the README there)";
}

TEST(PrimitiveMeshesTest, RevolutionRejectsBadProfiles) {
  EXPECT_FALSE(MakeSurfaceOfRevolution({{0, 0}, {0, 1}}, 8).ok());
  EXPECT_FALSE(MakeSurfaceOfRevolution({{1, 0}, {1, 1}, {0, 2}}, 8).ok());
  EXPECT_FALSE(MakeSurfaceOfRevolution({{0, 0}, {0, 1}, {0, 2}}, 8).ok());
  EXPECT_FALSE(MakeBottle(BottleShape{.neck_radius_mm = 50.0}).ok());
}

}  // namespace
}  // namespace surfmap
