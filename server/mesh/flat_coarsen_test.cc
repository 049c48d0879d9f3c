#include "server/mesh/flat_coarsen.h"

#include <algorithm>
#include <cmath>
#include <set>
#include <tuple>

#include <gtest/gtest.h>
#include "server/mesh/flat_refine.h"
#include "server/mesh/mesh_units.h"
#include "server/mesh/primitive_meshes.h"

namespace surfmap {
namespace {

using Key = std::tuple<double, double, double>;

std::set<Key> PositionSet(const ControlMesh& mesh) {
  std::set<Key> out;
  for (const Eigen::Vector3d& p : mesh.positions) out.insert({p.x(), p.y(), p.z()});
  return out;
}

// Every vertex of `coarse` is one of `fine`'s, unmoved.
void ExpectVerticesFrom(const ControlMesh& coarse, const ControlMesh& fine) {
  const std::set<Key> from = PositionSet(fine);
  for (const Eigen::Vector3d& p : coarse.positions) ASSERT_TRUE(from.count({p.x(), p.y(), p.z()})) << p.transpose();
}

double ThinnestShape(const ControlMesh& mesh) {
  double thinnest = 1.0;
  for (const auto& t : mesh.triangles) {
    const Eigen::Vector3d a = mesh.positions[t[0]], b = mesh.positions[t[1]], c = mesh.positions[t[2]];
    const double longest = std::max({(b - a).squaredNorm(), (c - b).squaredNorm(), (a - c).squaredNorm()});
    thinnest = std::min(thinnest, 0.5 * (b - a).cross(c - a).norm() / longest);
  }
  return thinnest;
}

// A CAD box tessellated at 2 mm (49,154 vertices) comes back as its 8
// corners and 12 triangles: every other vertex lies inside a face or in the
// middle of a straight edge.
TEST(CoarsenFlatTest, AFineBoxComesBackAsItsCorners) {
  absl::StatusOr<ControlMesh> fine = RefineFlat(MakeCadBox(50.0), 2.0, 100000);
  ASSERT_TRUE(fine.ok()) << fine.status();
  const ControlMesh coarse = CoarsenFlat(*fine);
  ASSERT_TRUE(ValidateControlMesh(coarse).ok()) << ValidateControlMesh(coarse);
  EXPECT_EQ(coarse.positions.size(), 8u);
  EXPECT_EQ(coarse.triangles.size(), 12u);
  ExpectVerticesFrom(coarse, *fine);
  // Area kept to rounding (the same six squares), so no face folded over.
  EXPECT_NEAR(SurfaceArea(coarse), 60000.0, 1e-6);
}

// The same box as a float STL in metres stores it: each coordinate rounded to
// a float, so faces are flat only to ~1e-6 of a facet (kFlatAngleTolerance
// is there for this).
TEST(CoarsenFlatTest, AFloatRoundedBoxInMetresStillCoarsens) {
  absl::StatusOr<ControlMesh> fine = RefineFlat(MakeCadBox(50.0), 2.5, 100000);
  ASSERT_TRUE(fine.ok()) << fine.status();
  for (Eigen::Vector3d& p : fine->positions) {
    for (int i = 0; i < 3; ++i) p[i] = 1000.0 * static_cast<double>(static_cast<float>(p[i] / 1000.0));
  }
  const ControlMesh coarse = CoarsenFlat(*fine);
  ASSERT_TRUE(ValidateControlMesh(coarse).ok()) << ValidateControlMesh(coarse);
  EXPECT_LE(coarse.positions.size(), 12u);
  ExpectVerticesFrom(coarse, *fine);
  EXPECT_NEAR(SurfaceArea(coarse), SurfaceArea(*fine), 1e-3);
}

// A curved surface has no flat region and no straight sharp edge: nothing moves.
TEST(CoarsenFlatTest, ACurvedSurfaceIsLeftAsItIs) {
  absl::StatusOr<ControlMesh> sphere = MakeIcosphere(40.0, 3);
  ASSERT_TRUE(sphere.ok());
  const ControlMesh coarse = CoarsenFlat(*sphere);
  EXPECT_EQ(coarse.positions, sphere->positions);
  EXPECT_EQ(coarse.triangles, sphere->triangles);
}

// A cylinder with flat caps, refined flat at 2 mm: the caps' insides and the
// side's straight lines go; the two rims (curved sharp edges) stay whole.
TEST(CoarsenFlatTest, ACylinderKeepsItsRimsAndLosesItsFlatInsides) {
  absl::StatusOr<ControlMesh> cylinder = MakeCylinder(30.0, 80.0, 64, 10);
  ASSERT_TRUE(cylinder.ok());
  absl::StatusOr<ControlMesh> fine = RefineFlat(*cylinder, 2.0, 200000);
  ASSERT_TRUE(fine.ok()) << fine.status();
  const ControlMesh coarse = CoarsenFlat(*fine);
  ASSERT_TRUE(ValidateControlMesh(coarse).ok()) << ValidateControlMesh(coarse);
  ExpectVerticesFrom(coarse, *fine);
  // Rim vertices: on the circle; chord midpoints: a little inside it, on
  // straight lines between two rim vertices.
  const auto count = [](const ControlMesh& mesh, double min_radius, double max_radius) {
    int n = 0;
    for (const Eigen::Vector3d& p : mesh.positions) {
      const double r = std::hypot(p.x(), p.y());
      n += (p.z() == 0.0 || p.z() == 80.0) && r >= min_radius && r <= max_radius;
    }
    return n;
  };
  EXPECT_EQ(count(*fine, 30.0 - 1e-9, 30.0 + 1e-9), 2 * 64);
  EXPECT_GT(count(*fine, 0.0, 30.0 - 1e-9), 1000);  // chord midpoints and the caps' insides
  EXPECT_EQ(count(coarse, 30.0 - 1e-9, 30.0 + 1e-9), 2 * 64);
  // One vertex stays inside each cap, and one on each of the side's 64
  // straight lines: a 64-gon triangulated from its rim alone, and an 80 mm
  // strip 2.9 mm wide as two triangles, would be thinner than
  // kMinCollapsedShape.
  EXPECT_EQ(count(coarse, 0.0, 30.0 - 1e-9), 2);
  EXPECT_EQ(coarse.positions.size(), 2u * 64 + 2 + 64);
  EXPECT_LT(coarse.positions.size(), fine->positions.size() / 20);
  EXPECT_NEAR(SurfaceArea(coarse), SurfaceArea(*fine), 1e-6 * SurfaceArea(*fine));
  EXPECT_GE(ThinnestShape(coarse), kMinCollapsedShape);
}

// An open flat plate keeps its border: a 40 x 40 grid comes back as its 4
// corners, and the border is not pinched across the inside.
TEST(CoarsenFlatTest, AnOpenPlateComesBackAsItsCorners) {
  absl::StatusOr<ControlMesh> plate = MakeGridPlate(100.0, 60.0, 40, 40);
  ASSERT_TRUE(plate.ok());
  const ControlMesh coarse = CoarsenFlat(*plate);
  ASSERT_TRUE(ValidateControlMesh(coarse).ok()) << ValidateControlMesh(coarse);
  EXPECT_EQ(coarse.positions.size(), 4u);
  EXPECT_EQ(coarse.triangles.size(), 2u);
  EXPECT_NEAR(SurfaceArea(coarse), 6000.0, 1e-9);
}

}  // namespace
}  // namespace surfmap
