#include "clients/sim/rig/scene_surface.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <gtest/gtest.h>
#include "clients/sim/rig/simulated_rig.h"
#include "server/estimate/fit_trace.h"
#include "server/mesh/primitive_meshes.h"

namespace surfmap {
namespace {

constexpr double kHalf = 50.0;  // the CAD box spans -50..50 mm on each axis

// A 100 mm CAD box of 12 triangles, one material.
Scene CadBoxScene(bool facets) {
  Scene scene;
  scene.name = "cad_box";
  scene.source = "test";
  scene.mesh = MakeCadBox(kHalf);
  scene.material_names = {"abs"};
  scene.materials = {Material{}};
  scene.materials[0].mu = 0.3;
  scene.facets = facets;
  return scene;
}

// How far `p` lies inside the box's surface (negative: outside).
double DepthInBox(const Eigen::Vector3d& p) { return kHalf - p.cwiseAbs().maxCoeff(); }

// Distance from `p` to the nearest of the box's 12 edges.
double DistanceToBoxEdge(const Eigen::Vector3d& p) {
  const Eigen::Vector3d a = p.cwiseAbs();
  double best = 1e300;
  for (int free_axis = 0; free_axis < 3; ++free_axis) {
    double d2 = 0.0;
    for (int k = 0; k < 3; ++k) {
      if (k != free_axis) d2 += (a[k] - kHalf) * (a[k] - kHalf);
    }
    best = std::min(best, std::sqrt(d2));
  }
  return best;
}

TEST(SceneSurfaceTest, AFacetsSceneIsItsFacetsAndAControlMeshSceneItsLoopSurface) {
  absl::StatusOr<std::unique_ptr<LoopSurface>> facets = SceneSurface(CadBoxScene(true), 4);
  ASSERT_TRUE(facets.ok()) << facets.status();
  const SurfaceLevel& fine = (*facets)->finest();
  // Every vertex is on a face: projected onto the facets, to rounding.
  for (const Eigen::Vector3d& p : fine.limit_positions) EXPECT_NEAR(DepthInBox(p), 0.0, 1e-9) << p.transpose();

  // The same 12 triangles taken as a Loop control mesh: a blob whose corners
  // lie well inside the box (by ~20 mm: why the service has facets uploads).
  absl::StatusOr<std::unique_ptr<LoopSurface>> loop = SceneSurface(CadBoxScene(false), 4);
  ASSERT_TRUE(loop.ok()) << loop.status();
  double deepest = 0.0;
  for (const Eigen::Vector3d& p : (*loop)->finest().limit_positions) deepest = std::max(deepest, DepthInBox(p));
  EXPECT_GT(deepest, 10.0);
}

TEST(SceneSurfaceTest, TheRigDragsAFacetsSceneOverASharpEdgeOnItsFaces) {
  SimulatedRigOptions options;
  options.surface_level = 3;  // edges of < 6 / 8 mm: the chamfer across the box's edges is that wide
  absl::StatusOr<std::unique_ptr<SimulatedRig>> rig = SimulatedRig::Create(CadBoxScene(true), options);
  ASSERT_TRUE(rig.ok()) << rig.status();
  // Centred 6 mm before the top face's edge at x = 50: 16 mm on the top, then
  // over the edge and 4 mm down the side.
  ProbeRequest request;
  request.position = {kHalf - 6.0, 0.0, kHalf};
  request.normal = Eigen::Vector3d::UnitZ();
  request.drag_direction = Eigen::Vector3d::UnitX();
  request.command_id = 1;
  absl::StatusOr<ProbeExecution> execution = (*rig)->ExecuteDetailed(request);
  ASSERT_TRUE(execution.ok()) << execution.status();
  EXPECT_NEAR(execution->length_mm, 20.0, 1e-6);
  const SurfacePath& path = execution->path;
  ASSERT_GE(path.points.size(), 2u);
  EXPECT_NEAR(path.points.front().z(), kHalf, 1e-6);
  EXPECT_NEAR(path.points.front().x(), kHalf - 16.0, 1.0);
  // It went over the edge: it ends on the side face, ~4 mm down, its normal +x.
  EXPECT_NEAR(path.points.back().x(), kHalf, 1e-6);
  EXPECT_NEAR(path.points.back().z(), kHalf - 4.0, 1.5);
  EXPECT_GT(path.normals.back().x(), 0.99);
  // One material, measured over the edge: the normal is unknown and turns
  // 90 degrees within ~1.5 mm, and the fit still reads the truth, on the
  // whole window and on every piece (the turn can split the drag: the force
  // changes its texture there).
  absl::StatusOr<TraceFit> fit = FitTrace(execution->trace, FitOptions{});
  ASSERT_TRUE(fit.ok()) << fit.status();
  EXPECT_NEAR(fit->friction.mu, 0.3, 0.005);
  for (const DragPiece& piece : fit->pieces) EXPECT_NEAR(piece.mu, 0.3, 0.01) << piece.start_mm;
  // The finest level's edges are ~6 / 8 mm (scene_surface.cc refines to 6
  // mm); the chamfer's triangles across the box's edges span up to two.
  const double edge_mm = 2.0 * 6.0 / 8.0;
  for (const Eigen::Vector3d& p : path.points) {
    if (DistanceToBoxEdge(p) > edge_mm) {
      EXPECT_NEAR(DepthInBox(p), 0.0, 1e-6) << p.transpose();
    } else {
      // Across the chamfer a level's triangles cut off the edge.
      EXPECT_LT(DepthInBox(p), 0.5 * edge_mm) << p.transpose();
      EXPECT_GT(DepthInBox(p), -1e-6) << p.transpose();
    }
  }
}

// A drag centred 4 mm above the bottom edge starts on the bottom face (the
// rig walks half a segment back over the edge) and comes back over it
// through the site, up the side: along the commanded line, not aside of it.
TEST(SceneSurfaceTest, ADragCentredBesideASharpEdgeRetracesItsWalkBackThroughTheSite) {
  absl::StatusOr<std::unique_ptr<SimulatedRig>> rig = SimulatedRig::Create(CadBoxScene(true));
  ASSERT_TRUE(rig.ok()) << rig.status();
  for (const Eigen::Vector3d& up : {Eigen::Vector3d(0, 0, 1), Eigen::Vector3d(0, 0.5, 0.866)}) {
    SCOPED_TRACE(up.transpose());
    ProbeRequest request;
    request.position = {kHalf, 0.0, -kHalf + 4.0};
    request.normal = Eigen::Vector3d::UnitX();
    request.drag_direction = up;
    request.command_id = 2;
    absl::StatusOr<ProbeExecution> execution = (*rig)->ExecuteDetailed(request);
    ASSERT_TRUE(execution.ok()) << execution.status();
    EXPECT_TRUE(execution->centred);
    const SurfacePath& path = execution->path;
    EXPECT_NEAR(path.points.front().z(), -kHalf, 1e-6);  // it starts on the bottom face
    double nearest = 1e300;
    for (const Eigen::Vector3d& p : path.points) nearest = std::min(nearest, (p - request.position).norm());
    EXPECT_LT(nearest, 0.5);
    // Seen along the site's normal, the forward chord is on the commanded line.
    Eigen::Vector3d chord = path.points.back() - path.points.front();
    chord.x() = 0.0;
    EXPECT_GT(chord.normalized().dot(up.normalized()), std::cos(10.0 * std::numbers::pi / 180));
  }
}

}  // namespace
}  // namespace surfmap
