#include "server/mesh/control_simplify.h"

#include <cmath>
#include <fstream>
#include <sstream>
#include <string>

#include "gtest/gtest.h"
#include "server/mesh/dense_surface.h"
#include "server/mesh/loop_surface.h"
#include "server/mesh/mesh_locator.h"
#include "server/mesh/mesh_units.h"
#include "server/mesh/primitive_meshes.h"
#include "server/mesh/scan_like_mesh.h"

namespace surfmap {
namespace {

TEST(ControlSimplify, DenseScanGivesAboutAreaOverSpacingSquaredVertices) {
  absl::StatusOr<ControlMesh> scan = MakeScanLikeMesh();
  ASSERT_TRUE(scan.ok());
  const double area = SurfaceArea(*scan);
  for (const double spacing : {10.0, 20.0}) {
    SCOPED_TRACE(spacing);
    absl::StatusOr<ControlMeshChoice> choice = ControlMeshForSpacing(*scan, spacing);
    ASSERT_TRUE(choice.ok()) << choice.status();
    EXPECT_TRUE(choice->simplified);
    const double expected = area / (spacing * spacing);
    EXPECT_EQ(choice->target_vertices, static_cast<int>(std::lround(expected)));
    // meshopt_simplify stops at the first collapse that reaches the index
    // target, so the count lands within a few vertices of it; 10 % leaves
    // room for the retries at 1.25x that a pinching collapse would force.
    EXPECT_NEAR(static_cast<double>(choice->mesh.positions.size()), expected, 0.1 * expected + 2);
    EXPECT_TRUE(ValidateControlMesh(choice->mesh).ok());
    // Mean edge length about the spacing (a regular triangulation of that
    // many vertices has 1.07 x); quadric simplification is not regular, so
    // +-35 %.
    double sum = 0;
    int edges = 0;
    for (const auto& t : choice->mesh.triangles) {
      for (int i = 0; i < 3; ++i) {
        sum += (choice->mesh.positions[t[i]] - choice->mesh.positions[t[(i + 1) % 3]]).norm();
        ++edges;
      }
    }
    EXPECT_NEAR(sum / edges, spacing, 0.35 * spacing);
  }
}

TEST(ControlSimplify, CoarseMeshIsUsedAsIs) {
  const ControlMesh octahedron = MakeOctahedron(50.0);  // area ~8,660 mm^2: 21 sites at 20 mm > 6 vertices
  absl::StatusOr<ControlMeshChoice> choice = ControlMeshForSpacing(octahedron, 20.0);
  ASSERT_TRUE(choice.ok());
  EXPECT_FALSE(choice->simplified);
  EXPECT_EQ(choice->mesh.positions, octahedron.positions);
  EXPECT_FALSE(ControlMeshForSpacing(octahedron, 0.0).ok());
}

// The bundled scenes' meshes were designed as control meshes: at the default
// spacing (the 20 mm drag) they must be planned as they always were.
TEST(ControlSimplify, BundledSceneMeshesAreKeptAtTheDefaultSpacing) {
  for (const char* name : {"banded_vase", "bottle", "dotted_egg", "plate", "strip_block", "torus_handle"}) {
    SCOPED_TRACE(name);
    std::ifstream in(std::string(SURFMAP_SOURCE_DIR) + "/clients/sim/scenes/" + name + ".obj");
    ASSERT_TRUE(in);
    std::ostringstream bytes;
    bytes << in.rdbuf();
    absl::StatusOr<ControlMesh> mesh = ParseControlMesh(bytes.str(), MeshFormat::kObj, name);
    ASSERT_TRUE(mesh.ok()) << mesh.status();
    absl::StatusOr<ControlMeshChoice> choice = ControlMeshForSpacing(*mesh, 20.0);
    ASSERT_TRUE(choice.ok()) << choice.status();
    EXPECT_FALSE(choice->simplified) << mesh->positions.size() << " vertices, target " << choice->target_vertices;
  }
}

TEST(ControlSimplify, ProjectedLoopSurfaceLiesOnTheDenseMesh) {
  absl::StatusOr<ControlMesh> scan = MakeScanLikeMesh();
  ASSERT_TRUE(scan.ok());
  absl::StatusOr<ControlMeshChoice> choice = ControlMeshForSpacing(*scan, 20.0);
  ASSERT_TRUE(choice.ok());
  const DenseSurface dense(*scan);
  absl::StatusOr<std::unique_ptr<LoopSurface>> surface = LoopSurface::Create(choice->mesh, 2, dense.Projection());
  ASSERT_TRUE(surface.ok()) << surface.status();
  const MeshLocator truth(scan->positions, scan->triangles);
  for (int k = 0; k <= 2; ++k) {
    const SurfaceLevel& level = (*surface)->level(k);
    for (std::size_t v = 0; v < level.limit_positions.size(); ++v) {
      const SurfacePoint hit = truth.Closest(level.limit_positions[v]);
      // On the dense surface (closest-point round-off only), and the normal
      // within 30 deg of the dense face's: interpolated vertex normals of a
      // noisy scan differ from a face's by the noise's slope (0.05 mm over
      // ~2 mm edges) and the bumps' curvature.
      ASSERT_LT(hit.distance, 1e-9) << "level " << k << " vertex " << v;
      ASSERT_GT(level.limit_normals[v].dot(hit.normal), std::cos(30.0 * M_PI / 180.0))
          << "level " << k << " vertex " << v;
    }
  }
  // Without projection, the coarse mesh's Loop surface is millimetres inside the scan.
  absl::StatusOr<std::unique_ptr<LoopSurface>> plain = LoopSurface::Create(choice->mesh, 0);
  ASSERT_TRUE(plain.ok());
  double worst = 0;
  for (const Eigen::Vector3d& p : (*plain)->level(0).limit_positions) worst = std::max(worst, truth.Closest(p).distance);
  EXPECT_GT(worst, 0.5);
}

}  // namespace
}  // namespace surfmap
