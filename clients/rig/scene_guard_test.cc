#include "clients/rig/scene_guard.h"

#include <chrono>

#include "clients/sim/rig/scene.h"
#include "clients/rig/realtime_driver.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "clients/sim/rig/simulated_rig.h"
#include "server/mesh/facets_surface.h"
#include "server/mesh/loop_surface.h"
#include "server/mesh/primitive_meshes.h"

namespace surfmap::rig {
namespace {

using ::testing::HasSubstr;

MeshFingerprint FingerprintOf(const ControlMesh& mesh, const std::string& name) {
  absl::StatusOr<std::unique_ptr<LoopSurface>> surface = LoopSurface::Create(mesh, 0);
  EXPECT_TRUE(surface.ok());
  return LevelFingerprint(name, (*surface)->level(0));
}

TEST(SceneGuard, SameMeshMatchesEvenAfterAUnitRoundTrip) {
  const ControlMesh mesh = MakeIcosahedron(40.0);
  ControlMesh via_metres = mesh;
  for (Eigen::Vector3d& p : via_metres.positions) p = (p / 1000.0) * 1000.0;  // an upload in m, stored in mm
  EXPECT_TRUE(CompareMeshes(FingerprintOf(mesh, "scene"), FingerprintOf(via_metres, "object")).ok());
}

TEST(SceneGuard, AnotherMeshIsRefusedNamingBoth) {
  const MeshFingerprint scene = FingerprintOf(MakeIcosahedron(40.0), "scene 'egg'");
  const absl::Status other = CompareMeshes(scene, FingerprintOf(MakeOctahedron(40.0), "job 3's object 2"));
  EXPECT_EQ(other.code(), absl::StatusCode::kFailedPrecondition);
  EXPECT_THAT(std::string(other.message()), HasSubstr("job 3's object 2: 6 vertices"));
  EXPECT_THAT(std::string(other.message()), HasSubstr("scene 'egg': 12 vertices"));
  // Same topology, one vertex moved by 0.1 mm.
  ControlMesh moved = MakeIcosahedron(40.0);
  moved.positions[5].x() += 0.1;
  const absl::Status shifted = CompareMeshes(scene, FingerprintOf(moved, "object"));
  EXPECT_EQ(shifted.code(), absl::StatusCode::kFailedPrecondition);
  EXPECT_THAT(std::string(shifted.message()), HasSubstr("away from the scene's"));
}

// A CAD scene's fingerprint is level 0 as the service serves an object
// uploaded as facets; the rig's own level 0 is the facets refined.
TEST(SceneGuard, AFacetsScenesFingerprintIsWhatTheServiceServesForFacets) {
  Scene scene;
  scene.name = "case";
  scene.mesh = MakeCadBox(40.0);
  scene.material_names = {"abs"};
  scene.materials = {Material{}};
  scene.facets = true;
  absl::StatusOr<std::unique_ptr<SimulatedRig>> rig = SimulatedRig::Create(scene);
  ASSERT_TRUE(rig.ok()) << rig.status();
  absl::StatusOr<MeshFingerprint> scene_print = SceneFingerprint(**rig);
  ASSERT_TRUE(scene_print.ok()) << scene_print.status();
  const MeshFingerprint& fingerprint = *scene_print;
  EXPECT_EQ(fingerprint.limit_positions.size(), 8u);
  EXPECT_GT((*rig)->surface().level(0).limit_positions.size(), 8u);
  absl::StatusOr<std::unique_ptr<LoopSurface>> served = ExactFacetsSurface(scene.mesh, 0);
  ASSERT_TRUE(served.ok()) << served.status();
  const MeshFingerprint object = LevelFingerprint("object", (*served)->level(0));
  EXPECT_TRUE(CompareMeshes(fingerprint, object).ok()) << CompareMeshes(fingerprint, object);
  // Which is the box's own corners.
  for (std::size_t v = 0; v < scene.mesh.positions.size(); ++v) {
    EXPECT_LT((fingerprint.limit_positions[v] - scene.mesh.positions[v]).norm(), 1e-9) << "corner " << v;
  }
  // The same box uploaded as a control mesh is served as its Loop limit: refused.
  EXPECT_FALSE(CompareMeshes(fingerprint, FingerprintOf(scene.mesh, "object")).ok());
}

class FixedTraceDriver : public RigDriver {
 public:
  absl::StatusOr<DragTrace> Execute(const ProbeRequest&) override {
    ++calls;
    DragTrace trace;
    for (int i = 0; i <= 30; ++i) trace.samples.push_back(DragSample{.t = 0.01 * i});
    return trace;
  }
  int calls = 0;
};

TEST(SceneGuard, DriverChecksEachJobOnceAndAbortsOnAnotherMesh) {
  FixedTraceDriver inner;
  int fetches = 0;
  const MeshFingerprint scene = FingerprintOf(MakeIcosahedron(40.0), "scene");
  SceneGuardDriver guard(inner, scene, [&](std::int64_t job) -> absl::StatusOr<MeshFingerprint> {
    ++fetches;
    return job == 1 ? FingerprintOf(MakeIcosahedron(40.0), "ok") : FingerprintOf(MakeOctahedron(40.0), "other");
  });
  ProbeRequest request;
  request.job_id = 1;
  EXPECT_TRUE(guard.Execute(request).ok());
  EXPECT_TRUE(guard.Execute(request).ok());
  request.job_id = 2;
  EXPECT_EQ(guard.Execute(request).status().code(), absl::StatusCode::kAborted);
  EXPECT_EQ(fetches, 2);
  EXPECT_EQ(inner.calls, 2);
}

TEST(RealtimeDriver, TakesTheTracesDuration) {
  FixedTraceDriver inner;  // 0.3 s of samples
  RealtimeDriver realtime(inner, nullptr);
  const auto start = std::chrono::steady_clock::now();
  ASSERT_TRUE(realtime.Execute(ProbeRequest{}).ok());
  const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  // At least the trace's 0.3 s; the upper bound allows a loaded 2-core machine's scheduling.
  EXPECT_GE(elapsed, 0.3);
  EXPECT_LT(elapsed, 1.5);
  std::atomic<bool> stop{true};
  RealtimeDriver stopped(inner, &stop);
  const auto start2 = std::chrono::steady_clock::now();
  ASSERT_TRUE(stopped.Execute(ProbeRequest{}).ok());
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start2).count(), 0.2);
}

}  // namespace
}  // namespace surfmap::rig
