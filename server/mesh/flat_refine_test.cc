#include "server/mesh/flat_refine.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <string>

#include <gtest/gtest.h>
#include "server/mesh/mesh_units.h"
#include "server/mesh/primitive_meshes.h"

namespace surfmap {
namespace {

// How far `p` lies from the surface of the box of half-size `half`.
double OffBox(const Eigen::Vector3d& p, double half) { return std::abs(p.cwiseAbs().maxCoeff() - half); }

double SmallestAngleDeg(const ControlMesh& m, const std::array<int, 3>& t) {
  double smallest = 180.0;
  for (int k = 0; k < 3; ++k) {
    const Eigen::Vector3d u = (m.positions[t[(k + 1) % 3]] - m.positions[t[k]]).normalized();
    const Eigen::Vector3d v = (m.positions[t[(k + 2) % 3]] - m.positions[t[k]]).normalized();
    smallest = std::min(smallest, std::acos(std::clamp(u.dot(v), -1.0, 1.0)) * 180.0 / M_PI);
  }
  return smallest;
}

double LongestEdge(const ControlMesh& m) {
  double longest = 0.0;
  for (const auto& t : m.triangles) {
    for (int k = 0; k < 3; ++k) longest = std::max(longest, (m.positions[t[k]] - m.positions[t[(k + 1) % 3]]).norm());
  }
  return longest;
}

TEST(RefineFlatTest, ABoxStaysTheBoxWithEveryEdgeShort) {
  const ControlMesh box = MakeCadBox(50.0);
  ASSERT_TRUE(ValidateControlMesh(box).ok());
  absl::StatusOr<ControlMesh> fine = RefineFlat(box, 2.0, 100000);
  ASSERT_TRUE(fine.ok()) << fine.status();
  EXPECT_TRUE(ValidateControlMesh(*fine).ok()) << ValidateControlMesh(*fine);  // manifold, one winding
  EXPECT_GT(fine->positions.size(), 10000u);
  for (int i = 0; i < 8; ++i) EXPECT_EQ(fine->positions[i], box.positions[i]) << "old vertices keep their index";
  double off = 0.0;
  for (const Eigen::Vector3d& p : fine->positions) off = std::max(off, OffBox(p, 50.0));
  EXPECT_LT(off, 1e-12);  // midpoints of edges on the facets are on the facets
  for (const auto& t : fine->triangles) {
    // Each new triangle lies in one face of the box and faces out: its
    // normal is that face's axis.
    const Eigen::Vector3d a = fine->positions[t[0]], b = fine->positions[t[1]], c = fine->positions[t[2]];
    const Eigen::Vector3d n = (b - a).cross(c - a).normalized();
    const Eigen::Vector3d centre = (a + b + c) / 3.0;
    int axis = 0;
    centre.cwiseAbs().maxCoeff(&axis);
    ASSERT_NEAR(n[axis], centre[axis] > 0 ? 1.0 : -1.0, 1e-12);
  }
  EXPECT_LE(LongestEdge(*fine), 2.0);
  EXPECT_NEAR(SurfaceArea(*fine), 6 * 100.0 * 100.0, 1e-6);
}

// A cylinder's side exported as long strips: every edge ends up short, and
// no angle ends much smaller than the strip's own 1.7-degree corners
// (bisecting the longest edge keeps at least about half the smallest angle;
// it does not widen slivers: the projection needs short edges, not round
// triangles).
TEST(RefineFlatTest, LongThinTrianglesGetShortEdgesAndNoThinnerAngles) {
  ControlMesh strip;
  strip.positions = {{0, 0, 0}, {3, 0, 0}, {0, 100, 0}, {3, 100, 0}};
  strip.triangles = {{0, 1, 3}, {0, 3, 2}};
  double before = 180.0;
  for (const auto& t : strip.triangles) before = std::min(before, SmallestAngleDeg(strip, t));
  absl::StatusOr<ControlMesh> fine = RefineFlat(strip, 2.0, 100000);
  ASSERT_TRUE(fine.ok()) << fine.status();
  double after = 180.0;
  for (const auto& t : fine->triangles) after = std::min(after, SmallestAngleDeg(*fine, t));
  EXPECT_NEAR(before, 1.718, 0.001);
  EXPECT_GE(after, 0.5 * before);
  EXPECT_LE(LongestEdge(*fine), 2.0);
  EXPECT_NEAR(SurfaceArea(*fine), 300.0, 1e-9);
}

TEST(RefineFlatTest, RefusesBadLengthsAndTooManyVerticesBeforeMakingThem) {
  EXPECT_EQ(RefineFlat(MakeCadBox(50.0), 0.0, 1000).status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(RefineFlat(MakeCadBox(50.0), std::nan(""), 1000).status().code(), absl::StatusCode::kInvalidArgument);
  const absl::Status too_many = RefineFlat(MakeCadBox(50.0), 0.01, 5000).status();
  EXPECT_EQ(too_many.code(), absl::StatusCode::kResourceExhausted);
  EXPECT_NE(too_many.message().find("more than 5000 vertices"), std::string::npos) << too_many;
}

TEST(RefineFlatTest, TheEdgeLengthGrowsWithTheObjectToKeepTheVertexCount) {
  EXPECT_EQ(FacetedRefineEdgeMm(60000.0, 200000), 2.0);  // a 100 mm box: 2 mm
  const double metre_box = FacetedRefineEdgeMm(6e6, 200000);  // a 1 m box
  EXPECT_NEAR(4.0 * 6e6 / (metre_box * metre_box), 200000, 1.0);
  absl::StatusOr<ControlMesh> fine = RefineFlat(MakeCadBox(500.0), metre_box, 400000);
  ASSERT_TRUE(fine.ok()) << fine.status();
  EXPECT_LT(fine->positions.size(), 200000u);  // about 4 x area / length^2 (3.3 on the 100 mm box)
}

}  // namespace
}  // namespace surfmap
