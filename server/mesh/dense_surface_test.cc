#include "server/mesh/dense_surface.h"

#include <cmath>

#include <gtest/gtest.h>
#include "server/mesh/flat_refine.h"
#include "server/mesh/primitive_meshes.h"

namespace surfmap {
namespace {

constexpr double kBoxHalf = 50.0;  // a 100 mm box

// The box's facets refined flat to 2 mm edges, as a facets object's surface is.
ControlMesh FineCadBox() {
  absl::StatusOr<ControlMesh> fine = RefineFlat(MakeCadBox(kBoxHalf), 2.0, 100000);
  EXPECT_TRUE(fine.ok()) << fine.status();
  return fine.ok() ? *fine : ControlMesh{};
}

// The normal projected at a point on the top face `from_edge_mm` before its
// edge at x = 50.
Eigen::Vector3d NormalBesideTheEdge(const DenseSurface& surface, double from_edge_mm) {
  Eigen::Vector3d p(kBoxHalf - from_edge_mm, 3.3, kBoxHalf + 0.1), n = Eigen::Vector3d::UnitX();
  surface.Project(p, n);
  EXPECT_NEAR(p.z(), kBoxHalf, 1e-12);
  return n;
}

// Smoothed across a box's edge (a scan's normals), a point 0.2 mm from it
// reads a normal leaning towards the side face; with the CAD crease it reads
// the top face's own, right up to the edge (on it, either face's).
TEST(DenseSurfaceTest, ACreaseKeepsEachFacesNormalUpToASharpEdge) {
  const ControlMesh fine = FineCadBox();
  const DenseSurface smooth(fine);
  const DenseSurface creased(fine, kCadCreaseAngleDeg);
  EXPECT_LT(NormalBesideTheEdge(smooth, 0.2).z(), 0.95);
  EXPECT_GT(NormalBesideTheEdge(smooth, 0.2).x(), 0.3);
  for (double from_edge : {0.01, 0.2, 1.0, 10.0}) {
    SCOPED_TRACE(from_edge);
    EXPECT_NEAR((NormalBesideTheEdge(creased, from_edge) - Eigen::Vector3d::UnitZ()).norm(), 0.0, 1e-12);
  }
  // Mid-face both agree.
  EXPECT_NEAR((NormalBesideTheEdge(smooth, 10.0) - Eigen::Vector3d::UnitZ()).norm(), 0.0, 1e-12);
}

// Below the crease normals are smoothed as before: on an icosphere (faces
// meeting at ~10 degrees) the creased and the smooth normals agree closely.
TEST(DenseSurfaceTest, BelowTheCreaseNormalsAreSmooth) {
  absl::StatusOr<ControlMesh> sphere = MakeIcosphere(40.0, 3);
  ASSERT_TRUE(sphere.ok()) << sphere.status();
  const DenseSurface smooth(*sphere);
  const DenseSurface creased(*sphere, kCadCreaseAngleDeg);
  for (const Eigen::Vector3d& dir : {Eigen::Vector3d(1, 2, 3), Eigen::Vector3d(-2, 0.5, 1), Eigen::Vector3d(0.3, -1, -2)}) {
    Eigen::Vector3d p1 = 40.0 * dir.normalized(), n1 = Eigen::Vector3d::UnitZ();
    Eigen::Vector3d p2 = p1, n2 = n1;
    smooth.Project(p1, n1);
    creased.Project(p2, n2);
    // Area against angle weights differ by a fraction of a degree here.
    EXPECT_GT(n1.dot(n2), std::cos(0.5 * 3.14159265358979 / 180)) << dir.transpose();
    // Both are near the true radial direction (the facets' own is up to ~5 degrees off).
    EXPECT_GT(n2.dot(p2.normalized()), std::cos(1.0 * 3.14159265358979 / 180)) << dir.transpose();
  }
}

}  // namespace
}  // namespace surfmap
