// Bring your own mesh, through the real server: a dense scan-like mesh in
// metres with stray vertices, STL (binary and ASCII) and a polygon with a
// repeated vertex upload with units and are repaired with a report; a job on
// the dense object plans about area / spacing^2 level-0 sites on a
// simplified control mesh, with every site on the dense surface and a robot
// time estimate; the simulated rig refuses a job on another mesh; and the
// dense object is mapped end to end by simulated rigs and scored on its true
// (dense) surface.
#include <cmath>
#include <map>
#include <string>
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_replace.h"
#include "clients/sim/rig/surface_score.h"
#include "gtest/gtest.h"
#include "server/mesh/mesh_locator.h"
#include "server/mesh/primitive_meshes.h"
#include "server/mesh/scan_like_mesh.h"
#include "tests/support/child_process.h"
#include "tests/support/job_helpers.h"
#include "tests/support/rig_fleet.h"
#include "tests/support/server_process.h"
#include "tests/support/status_matchers.h"

#ifndef SURFMAP_RIG_PATH
#define SURFMAP_RIG_PATH "surfmap-rig"
#endif

namespace surfmap::itest {
namespace {

using std::chrono::seconds;

constexpr int kStrayVertices = 37;

absl::StatusOr<pb::UploadObjectResponse> Upload(Stubs& stubs, const std::string& name, pb::MeshFormat format,
                                                const std::string& bytes, pb::LengthUnit units) {
  pb::UploadObjectRequest request;
  request.set_name(name);
  request.set_format(format);
  request.set_mesh(bytes);
  request.set_units(units);
  pb::UploadObjectResponse response;
  grpc::Status status = stubs.objects->UploadObject(Context(120).get(), request, &response);
  if (!status.ok()) return FromGrpc(status, "UploadObject(" + name + ")");
  return response;
}

int RepairCount(const pb::UploadObjectResponse& response, const std::string& kind) {
  for (const pb::MeshRepair& r : response.repairs()) {
    if (r.kind() == kind) return r.count();
  }
  return 0;
}

absl::StatusOr<pb::CreateJobResponse> CreateJobFull(Stubs& stubs, const pb::JobSpec& spec) {
  pb::CreateJobRequest request;
  *request.mutable_spec() = spec;
  pb::CreateJobResponse response;
  grpc::Status status = stubs.jobs->CreateJob(Context(120).get(), request, &response);
  if (!status.ok()) return FromGrpc(status, "CreateJob");
  return response;
}

TEST(ScannedMesh, UploadsWithUnitsAreRepairedAndPlannedAtTheSpacing) {
  ITEST_ASSERT_OK_AND_ASSIGN(server, ServerProcess::Start());
  Stubs stubs(server->channel());
  ITEST_ASSERT_OK_AND_ASSIGN(scan, MakeScanLikeMesh());
  ASSERT_GE(scan.triangles.size(), 20000u);
  const std::string in_metres = WriteObjScaled(scan, 1000.0, kStrayVertices);

  // Metres read as mm: a 0.12 mm object, refused with the reason.
  absl::StatusOr<pb::UploadObjectResponse> as_mm =
      Upload(stubs, "scan", pb::MESH_FORMAT_OBJ, in_metres, pb::LENGTH_UNIT_MM);
  ASSERT_FALSE(as_mm.ok());
  EXPECT_EQ(as_mm.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(as_mm.status().message().find("implausibly small"), std::string::npos) << as_mm.status();

  ITEST_ASSERT_OK_AND_ASSIGN(dense, Upload(stubs, "scan", pb::MESH_FORMAT_OBJ, in_metres, pb::LENGTH_UNIT_M));
  EXPECT_EQ(RepairCount(dense, "unreferenced_vertices_removed"), kStrayVertices);
  EXPECT_EQ(dense.object().control_vertex_count(), static_cast<int>(scan.positions.size()));
  EXPECT_DOUBLE_EQ(dense.scale_mm(), 1000.0);
  EXPECT_NEAR(dense.extent_mm().x(), 120.0, 5.0);  // radius 60 mm +- 1.5 mm bumps
  EXPECT_TRUE(dense.warnings().empty());

  // STL, binary and ASCII, in mm: the same mesh.
  for (const bool binary : {true, false}) {
    ITEST_ASSERT_OK_AND_ASSIGN(
        stl, Upload(stubs, binary ? "scan_bin" : "scan_ascii", pb::MESH_FORMAT_STL,
                    binary ? WriteStlBinary(scan) : WriteStlAscii(scan), pb::LENGTH_UNIT_MM));
    EXPECT_EQ(stl.object().control_vertex_count(), static_cast<int>(scan.positions.size()));
    EXPECT_EQ(stl.object().control_face_count(), static_cast<int>(scan.triangles.size()));
  }

  // A polygon with a repeated vertex: fixed and reported.
  ITEST_ASSERT_OK_AND_ASSIGN(ball, MakeIcosphere(40.0, 2));
  std::string obj = WriteObj(ball);
  const auto& t0 = ball.triangles[0];
  const std::string first = absl::StrCat("f ", t0[0] + 1, " ", t0[1] + 1, " ", t0[2] + 1, "\n");
  const std::string repeated = absl::StrCat("f ", t0[0] + 1, " ", t0[1] + 1, " ", t0[1] + 1, " ", t0[2] + 1, "\n");
  ASSERT_NE(obj.find(first), std::string::npos);
  obj.replace(obj.find(first), first.size(), repeated);
  ITEST_ASSERT_OK_AND_ASSIGN(fixed, Upload(stubs, "ball", pb::MESH_FORMAT_OBJ, obj, pb::LENGTH_UNIT_MM));
  EXPECT_EQ(RepairCount(fixed, "repeated_vertex_polygons_fixed"), 1);

  // A job at the default spacing (the 20 mm drag).
  JobSpecOptions options;
  options.finest_level = 1;
  ITEST_ASSERT_OK_AND_ASSIGN(created, CreateJobFull(stubs, MakeJobSpec(dense.object().object_id(), options)));
  const pb::PlanEstimate& e = created.estimate();
  const double expected_sites = dense.area_mm2() / (20.0 * 20.0);
  std::cout << "dense scan: area " << dense.area_mm2() << " mm^2, area/spacing^2 " << expected_sites
            << ", level-0 sites " << e.level0_sites() << ", spacing " << e.control_spacing_mm() << " mm, expected "
            << e.expected_sites() << " sites, " << e.expected_time().seconds() << " s\n";
  // meshopt_simplify stops within a few vertices of its target (the unit
  // test: within 10 %); 15 % fails a plan that fell back to a less
  // aggressive retry (1.25x) or was not simplified at all (10,242 sites).
  EXPECT_NEAR(e.level0_sites(), expected_sites, 0.15 * expected_sites);
  EXPECT_TRUE(e.simplified());
  EXPECT_NEAR(e.control_spacing_mm(), 20.0, 0.35 * 20.0);
  // 3 s approach + 2 x 20 mm / 10 mm/s + 0.5 s pause.
  EXPECT_DOUBLE_EQ(e.seconds_per_drag(), 7.5);
  EXPECT_NEAR(static_cast<double>(e.level0_time().seconds()), 7.5 * e.level0_sites(), 1.0);
  EXPECT_GE(e.expected_sites(), e.level0_sites());
  EXPECT_TRUE(created.warnings().empty()) << created.warnings(0);

  // The plan's level-0 sites: as many as estimated, all on the dense surface.
  ITEST_ASSERT_OK_AND_ASSIGN(plan, GetPlan(stubs, created.job().job_id()));
  const MeshLocator truth(scan.positions, scan.triangles);
  int level0 = 0;
  double worst = 0;
  for (const pb::PlanSite& site : plan.sites()) {
    if (site.site().level() != 0) continue;
    ++level0;
    worst = std::max(worst, truth.Closest({site.position().x(), site.position().y(), site.position().z()}).distance);
  }
  EXPECT_EQ(level0, e.level0_sites());
  // The stored mesh is the scan x 1000 / 1000 (text round trip): 1e-9 mm.
  EXPECT_LT(worst, 1e-6);

  // Closer sites than the drag: a warning. A drag longer than the object: refused.
  pb::JobSpec close = MakeJobSpec(dense.object().object_id(), options);
  close.set_site_spacing_mm(10.0);
  ITEST_ASSERT_OK_AND_ASSIGN(warned, CreateJobFull(stubs, close));
  ASSERT_EQ(warned.warnings_size(), 1);
  EXPECT_NE(warned.warnings(0).find("closer than 3/4 of the drag"), std::string::npos) << warned.warnings(0);
  // BOUNDARY's default spacing is 0.65 of the drag (13 mm): its budget is 1.5
  // drags per level-0 site, and a drag apart the scan-like held-out scenes
  // lost whole features. Its drags overlap on purpose: no warning.
  JobSpecOptions boundary_options = options;
  boundary_options.mode = pb::SAMPLING_MODE_BOUNDARY;
  ITEST_ASSERT_OK_AND_ASSIGN(boundary, CreateJobFull(stubs, MakeJobSpec(dense.object().object_id(), boundary_options)));
  EXPECT_DOUBLE_EQ(boundary.job().spec().site_spacing_mm(), 13.0);
  const double boundary_sites = dense.area_mm2() / (13.0 * 13.0);
  EXPECT_NEAR(boundary.estimate().level0_sites(), boundary_sites, 0.15 * boundary_sites);
  EXPECT_TRUE(boundary.estimate().simplified());
  EXPECT_EQ(boundary.estimate().max_sites(), boundary.estimate().level0_sites() * 3 / 2);
  EXPECT_TRUE(boundary.warnings().empty()) << boundary.warnings(0);
  EXPECT_DOUBLE_EQ(created.job().spec().site_spacing_mm(), 20.0);  // ADAPTIVE: the drag length

  pb::JobSpec long_drag = MakeJobSpec(dense.object().object_id(), options);
  long_drag.mutable_probe()->set_segment_length_mm(150.0);
  absl::StatusOr<pb::CreateJobResponse> refused = CreateJobFull(stubs, long_drag);
  ASSERT_FALSE(refused.ok());
  EXPECT_EQ(refused.status().code(), absl::StatusCode::kFailedPrecondition);
  EXPECT_NE(refused.status().message().find("longer than the object"), std::string::npos) << refused.status();

  // The simulated rig of another scene refuses the job, naming both meshes.
  ITEST_ASSERT_OK_AND_ASSIGN(
      rig, ChildProcess::Start({SURFMAP_RIG_PATH, "--server", server->address(), "--job",
                                std::to_string(created.job().job_id()), "--sim", "bottle", "--quiet", "--spool",
                                server->dir() + "/spool"},
                               server->dir() + "/rig.log"));
  ITEST_ASSERT_OK_AND_ASSIGN(exit_code, rig->Wait(seconds(120)));
  const std::string output = rig->Output();
  EXPECT_NE(exit_code, 0) << output;
  EXPECT_NE(output.find("is not this simulated rig's scene (scene 'bottle'"), std::string::npos) << output;
}

// The scan as a scene: glass, with the cap x > 20 mm of sandpaper.
Scene DenseScene(const ControlMesh& mesh) {
  Scene scene;
  scene.name = "dense_pebble";
  scene.mesh = mesh;
  scene.material_names = {"glass", "sandpaper"};
  scene.materials = {kGlass, Material{0.5, 0.30, 0.10, 0.25}};
  scene.default_material = 0;
  SceneRegion cap;
  cap.material = 1;
  cap.shape = BoxRegion{Eigen::Vector3d(20, -100, -100), Eigen::Vector3d(100, 100, 100)};
  scene.regions = {cap};
  scene.seed = 4242;
  return scene;
}

TEST(ScannedMesh, DenseObjectIsMappedEndToEndOnItsTrueSurface) {
  ITEST_ASSERT_OK_AND_ASSIGN(server, ServerProcess::Start());
  Stubs stubs(server->channel());
  ITEST_ASSERT_OK_AND_ASSIGN(scan, MakeScanLikeMesh());
  const Scene scene = DenseScene(scan);
  // The rig touches the scan itself, refined once (82k triangles; the Loop
  // limit of a dense mesh lies within its bumps' curvature of it).
  SimulatedRigOptions rig_options;
  rig_options.surface_level = 1;
  ITEST_ASSERT_OK_AND_ASSIGN(rig, SimulatedRig::Create(scene, rig_options));
  ITEST_ASSERT_OK_AND_ASSIGN(
      uploaded, Upload(stubs, "pebble", pb::MESH_FORMAT_OBJ, WriteObjScaled(scan, 1000.0, kStrayVertices),
                       pb::LENGTH_UNIT_M));
  JobSpecOptions options;
  options.finest_level = 1;
  options.threshold = 2.0;  // glass vs sandpaper is ~8 texture-distance units
  ITEST_ASSERT_OK_AND_ASSIGN(created, CreateJobFull(stubs, MakeJobSpec(uploaded.object().object_id(), options)));
  RigFleetOptions fleet_options;
  fleet_options.rigs = 2;
  fleet_options.job_id = created.job().job_id();
  RigFleetRecord record = RigFleet(server->address(), *rig, fleet_options).Run();
  ASSERT_TRUE(record.rpc_errors.empty()) << record.rpc_errors[0];
  ITEST_ASSERT_OK_AND_ASSIGN(done, WaitForJobState(stubs, created.job().job_id(), pb::JOB_STATE_COMPLETED,
                                                   seconds(60)));
  EXPECT_GE(done.progress().measured(), created.estimate().level0_sites() * 9 / 10);

  SurfaceScoreOptions score_options;
  score_options.truth_level = 1;  // the dense mesh refined once is the truth (level 4 would be 5M triangles)
  score_options.points = 2000;
  ITEST_ASSERT_OK_AND_ASSIGN(scorer, SurfaceScorer::Create(scene, score_options));
  const int64_t job_id = created.job().job_id();
  MapReader read = [&](const Eigen::Vector3d& p) -> absl::StatusOr<MapReading> {
    pb::QueryMapRequest request;
    request.set_job_id(job_id);
    pb::Vec3* point = request.add_points();
    point->set_x(p.x());
    point->set_y(p.y());
    point->set_z(p.z());
    pb::QueryMapResponse response;
    grpc::Status status = stubs.maps->QueryMap(Context(30).get(), request, &response);
    if (!status.ok()) return FromGrpc(status, "QueryMap");
    MapReading r;
    r.mu = response.values(0).mu();
    return r;
  };
  ITEST_ASSERT_OK_AND_ASSIGN(score, scorer.Score(read));
  std::cout << FormatSurfaceScore(score, "dense pebble, adaptive L0-1, default spacing") << "\n";
  std::cout << "samples " << done.progress().measured() << " (level-0 sites " << created.estimate().level0_sites()
            << ")\n";
  // Measured 2026-11-29: 99.65 % classified right, mu RMSE 0.023 with 105
  // samples (69 level-0 sites). The map level moved onto this scan's bumps
  // has slivers; before cotangents were capped (mesh_laplacian.cc) their
  // weights (~1e299) scrambled the random walker and 920 vertices 5-15 mm
  // from the boundary took the other side: 97.80 %, 0.058, boundary error
  // p90 10 mm. The floors fail that, a map whose sites are off the surface
  // (drags refused or on the wrong side) or a plan that missed the cap's
  // boundary, and leave the rigs' interleaving ~1 % of room.
  EXPECT_GE(score.classified_right, 0.985);
  EXPECT_LE(score.mu_rmse, 0.04);
}

}  // namespace
}  // namespace surfmap::itest
