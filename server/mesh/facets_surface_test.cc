#include "server/mesh/facets_surface.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <gtest/gtest.h>
#include "server/mesh/primitive_meshes.h"

namespace surfmap {
namespace {

constexpr double kHalf = 50.0;  // a 100 mm box

double OffBox(const Eigen::Vector3d& p) { return std::abs(p.cwiseAbs().maxCoeff() - kHalf); }

// How far `p` (on the box) lies from the box's nearest edge.
double FromEdge(const Eigen::Vector3d& p) {
  Eigen::Vector3d a = p.cwiseAbs();
  std::sort(a.data(), a.data() + 3);
  return kHalf - a[1];  // the second largest coordinate reaches kHalf on an edge
}

TEST(FacetsSurfaceTest, AsAControlMeshA12TriangleBoxIsABlob) {
  absl::StatusOr<std::unique_ptr<LoopSurface>> blob = LoopSurface::Create(MakeCadBox(kHalf), 2);
  ASSERT_TRUE(blob.ok()) << blob.status();
  double off = 0.0;
  for (const Eigen::Vector3d& p : (*blob)->level(2).limit_positions) off = std::max(off, OffBox(p));
  EXPECT_GT(off, 10.0) << "why facets exist: the limit surface lies centimetres inside the box";
}

TEST(FacetsSurfaceTest, SitesLieOnTheFacetsWithTheFacesNormals) {
  for (double spacing : {13.0, 20.0, 0.0}) {
    SCOPED_TRACE(spacing);
    absl::StatusOr<std::unique_ptr<LoopSurface>> surface = FacetsSurface(MakeCadBox(kHalf), 2, spacing);
    ASSERT_TRUE(surface.ok()) << surface.status();
    const SurfaceLevel& level0 = (*surface)->level(0);
    if (spacing > 0) {
      // About area / spacing^2 control vertices, as a scan's control mesh.
      const double target = 6 * 100.0 * 100.0 / (spacing * spacing);
      EXPECT_GT(level0.limit_positions.size(), 0.5 * target);
      EXPECT_LT(level0.limit_positions.size(), 1.5 * target);
    } else {
      EXPECT_EQ(level0.limit_positions.size(), 8u);  // the facets themselves
    }
    const SurfaceLevel& fine = (*surface)->level(2);
    int inside_faces = 0;
    for (std::size_t v = 0; v < fine.limit_positions.size(); ++v) {
      const Eigen::Vector3d& p = fine.limit_positions[v];
      ASSERT_LT(OffBox(p), 1e-9) << "vertex " << v;
      // The normal is the face's own (not smoothed across the sharp edges:
      // dense_surface_test.cc): a site beside an edge is commanded with its
      // face's normal, which is what a rig feels there. On an edge either
      // face's will do.
      if (FromEdge(p) < 1e-9) continue;
      ++inside_faces;
      int axis = 0;
      p.cwiseAbs().maxCoeff(&axis);
      ASSERT_NEAR(fine.limit_normals[v][axis], p[axis] > 0 ? 1.0 : -1.0, 1e-9) << "vertex " << v;
    }
    EXPECT_GT(inside_faces, static_cast<int>(fine.limit_positions.size()) / 2);
  }
}

// The object's shape as GetMesh serves it. Taken as a smooth control mesh
// and projected back (FacetsSurface at spacing 0, the simulated rig's scene)
// the box's level-0 corners land on the faces far from the corners (measured
// 28 mm); with every edge sharp level 0 is the box's own 8 corners and every
// finer level lies on its faces, with its edges and corners where they are.
TEST(FacetsSurfaceTest, ExactFacetsAreTheBoxCornersAndAll) {
  const ControlMesh box = MakeCadBox(kHalf);
  absl::StatusOr<std::unique_ptr<LoopSurface>> smoothed = FacetsSurface(box, 3, /*site_spacing_mm=*/0);
  absl::StatusOr<std::unique_ptr<LoopSurface>> exact = ExactFacetsSurface(box, 3);
  ASSERT_TRUE(smoothed.ok()) << smoothed.status();
  ASSERT_TRUE(exact.ok()) << exact.status();
  double smoothed_corner_error = 0.0;
  for (std::size_t v = 0; v < box.positions.size(); ++v) {
    smoothed_corner_error =
        std::max(smoothed_corner_error, ((*smoothed)->level(0).limit_positions[v] - box.positions[v]).norm());
    EXPECT_LT(((*exact)->level(0).limit_positions[v] - box.positions[v]).norm(), 1e-9) << "corner " << v;
  }
  EXPECT_GT(smoothed_corner_error, 10.0);
  const SurfaceLevel& fine = (*exact)->level(3);
  int on_edges = 0;
  for (std::size_t v = 0; v < fine.limit_positions.size(); ++v) {
    const Eigen::Vector3d& p = fine.limit_positions[v];
    ASSERT_LT(OffBox(p), 1e-9) << "vertex " << v;
    if (FromEdge(p) < 1e-9) {
      ++on_edges;
      continue;
    }
    int axis = 0;
    p.cwiseAbs().maxCoeff(&axis);
    ASSERT_NEAR(fine.limit_normals[v][axis], p[axis] > 0 ? 1.0 : -1.0, 1e-9) << "vertex " << v;
  }
  // Each of the 12 edges keeps 2^3 + 1 vertices on it at level 3 (the corners
  // shared by three edges): 12 x 7 + 8.
  EXPECT_EQ(on_edges, 12 * 7 + 8);
  // Every level's triangles are flat pieces of the faces: none spans an edge.
  for (const auto& t : fine.triangles) {
    const Eigen::Vector3d centroid =
        (fine.limit_positions[t[0]] + fine.limit_positions[t[1]] + fine.limit_positions[t[2]]) / 3.0;
    ASSERT_LT(OffBox(centroid), 1e-9);
  }
}

// A cylinder exported as 16 segments: its rims are sharp (90 degrees), its
// segments meet at 22.5 (a tessellated curve). The caps' normals are the
// caps' and the side's horizontal up to the rims, and across the segments
// they are never further from the true radial direction than a segment's own
// face normal (dense_surface_test.cc tests the crease itself).
TEST(FacetsSurfaceTest, ATessellatedCylindersRimsStaySharp) {
  constexpr double kRadius = 30.0, kHeight = 60.0;
  absl::StatusOr<ControlMesh> cylinder = MakeCylinder(kRadius, kHeight, 16, 4);
  ASSERT_TRUE(cylinder.ok()) << cylinder.status();
  absl::StatusOr<std::unique_ptr<LoopSurface>> surface = FacetsSurface(*cylinder, 3, 13.0);
  ASSERT_TRUE(surface.ok()) << surface.status();
  const SurfaceLevel& fine = (*surface)->finest();
  const double half_segment = std::numbers::pi / 16;
  int side = 0, caps = 0, rim = 0;
  for (std::size_t v = 0; v < fine.limit_positions.size(); ++v) {
    const Eigen::Vector3d& p = fine.limit_positions[v];
    const Eigen::Vector3d& n = fine.limit_normals[v];
    const bool on_cap = p.z() < 1e-9 || p.z() > kHeight - 1e-9;
    const bool on_rim = on_cap && std::hypot(p.x(), p.y()) >= kRadius * std::cos(half_segment) - 1e-6;
    if (on_rim) {
      ++rim;  // on the edge itself: either side's normal
    } else if (on_cap) {
      ++caps;
      EXPECT_NEAR(std::abs(n.z()), 1.0, 1e-9) << "cap vertex " << v;
    } else {
      ++side;
      EXPECT_NEAR(n.z(), 0.0, 1e-9) << "side vertex " << v;
      const Eigen::Vector3d radial = Eigen::Vector3d(p.x(), p.y(), 0).normalized();
      EXPECT_GT(n.dot(radial), std::cos(half_segment) - 1e-9) << "side vertex " << v;
    }
  }
  EXPECT_GT(side, 100);
  EXPECT_GT(caps, 20);
}

}  // namespace
}  // namespace surfmap
