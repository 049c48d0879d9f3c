// A CAD export through the real server: a 100 mm box as 12 triangles, in
// metres. Uploaded as FACETS, every surface point the service serves (the
// mesh, its corners where they are; the plan's sites, a leased command) lies
// on the box, with the face's
// own normal away from its edges; uploaded as a control mesh (the default),
// its Loop limit surface is a blob centimetres inside the box.
#include <algorithm>
#include <cmath>
#include <iostream>
#include <string>

#include "gtest/gtest.h"
#include "server/mesh/flat_refine.h"
#include "server/mesh/primitive_meshes.h"
#include "server/mesh/scan_like_mesh.h"
#include "tests/support/job_helpers.h"
#include "tests/support/server_process.h"
#include "tests/support/status_matchers.h"

namespace surfmap::itest {
namespace {

constexpr double kHalf = 50.0;

Eigen::Vector3d BoxPoint(const pb::Vec3& v) { return {v.x(), v.y(), v.z()}; }
double OffCadBox(const Eigen::Vector3d& p) { return std::abs(p.cwiseAbs().maxCoeff() - kHalf); }
double FromCadBoxEdge(const Eigen::Vector3d& p) {
  Eigen::Vector3d a = p.cwiseAbs();
  std::sort(a.data(), a.data() + 3);
  return kHalf - a[1];
}

absl::StatusOr<pb::UploadObjectResponse> UploadBox(Stubs& stubs, pb::ObjectSurface surface,
                                                   double facet_edge_mm = 0) {
  pb::UploadObjectRequest request;
  request.set_name("cad_box");
  if (facet_edge_mm > 0) {
    // A finely tessellated export, as a binary STL (float coordinates).
    absl::StatusOr<ControlMesh> fine = RefineFlat(MakeCadBox(kHalf), facet_edge_mm, 200000);
    if (!fine.ok()) return fine.status();
    request.set_format(pb::MESH_FORMAT_STL);
    request.set_mesh(WriteStlBinary(*fine, 1000.0));
  } else {
    request.set_format(pb::MESH_FORMAT_OBJ);
    request.set_mesh(WriteObjScaled(MakeCadBox(kHalf), 1000.0, 0));  // in metres, as CAD exports often are
  }
  request.set_units(pb::LENGTH_UNIT_M);
  request.set_surface(surface);
  pb::UploadObjectResponse response;
  grpc::Status status = stubs.objects->UploadObject(Context(120).get(), request, &response);
  if (!status.ok()) return FromGrpc(status, "UploadObject");
  return response;
}

absl::StatusOr<double> MeshOffCadBox(Stubs& stubs, std::int64_t object_id) {
  pb::GetMeshRequest request;
  request.set_object_id(object_id);
  request.set_level(2);
  pb::GetMeshResponse mesh;
  grpc::Status status = stubs.objects->GetMesh(Context(60).get(), request, &mesh);
  if (!status.ok()) return FromGrpc(status, "GetMesh");
  double off = 0.0;
  for (const pb::Vec3& p : mesh.positions()) off = std::max(off, OffCadBox(BoxPoint(p)));
  return off;
}

TEST(CadMesh, ABoxUploadedAsFacetsIsPlannedAndCommandedOnItsFaces) {
  ITEST_ASSERT_OK_AND_ASSIGN(server, ServerProcess::Start());
  Stubs stubs(server->channel());

  ITEST_ASSERT_OK_AND_ASSIGN(blob, UploadBox(stubs, pb::OBJECT_SURFACE_UNSPECIFIED));
  EXPECT_EQ(blob.object().surface(), pb::OBJECT_SURFACE_CONTROL_MESH);
  ITEST_ASSERT_OK_AND_ASSIGN(blob_off, MeshOffCadBox(stubs, blob.object().object_id()));
  EXPECT_GT(blob_off, 10.0) << "as a control mesh the box is a blob";

  ITEST_ASSERT_OK_AND_ASSIGN(box, UploadBox(stubs, pb::OBJECT_SURFACE_FACETS));
  const std::int64_t object_id = box.object().object_id();
  EXPECT_EQ(box.object().surface(), pb::OBJECT_SURFACE_FACETS);
  EXPECT_EQ(box.object().control_vertex_count(), 8);  // stored as uploaded
  pb::GetObjectRequest get;
  get.set_object_id(object_id);
  pb::GetObjectResponse stored;
  ASSERT_TRUE(stubs.objects->GetObject(Context().get(), get, &stored).ok());
  EXPECT_EQ(stored.object().surface(), pb::OBJECT_SURFACE_FACETS);
  // The stored mesh is the box x 1000 / 1000 (text round trip).
  ITEST_ASSERT_OK_AND_ASSIGN(off, MeshOffCadBox(stubs, object_id));
  EXPECT_LT(off, 1e-6);
  // Level 0 is the box's own 8 corners (every edge sharp), not corners of
  // its Loop blob squashed onto the faces (28 mm off before).
  pb::GetMeshRequest level0_request;
  level0_request.set_object_id(object_id);
  level0_request.set_level(0);
  pb::GetMeshResponse level0;
  ASSERT_TRUE(stubs.objects->GetMesh(Context(60).get(), level0_request, &level0).ok());
  ASSERT_EQ(level0.positions_size(), 8);
  for (const pb::Vec3& p : level0.positions()) {
    EXPECT_LT((BoxPoint(p).cwiseAbs() - Eigen::Vector3d::Constant(kHalf)).cwiseAbs().maxCoeff(), 1e-6);
  }

  // The default job (BOUNDARY, 13 mm spacing): about area / spacing^2 sites,
  // every one on the box.
  pb::CreateJobRequest create;
  create.mutable_spec()->set_object_id(object_id);  // the rest left to the service
  create.mutable_spec()->set_property(pb::PROPERTY_FRICTION);
  pb::CreateJobResponse created;
  grpc::Status status = stubs.jobs->CreateJob(Context(120).get(), create, &created);
  ASSERT_TRUE(status.ok()) << status.error_message();
  const double target = 6 * 100.0 * 100.0 / (13.0 * 13.0);
  EXPECT_GT(created.estimate().level0_sites(), 0.5 * target);
  EXPECT_LT(created.estimate().level0_sites(), 1.5 * target);
  std::cout << "CAD box: as a control mesh up to " << blob_off << " mm off the box; as facets "
            << created.estimate().level0_sites() << " level-0 sites (area / spacing^2 = " << target << ")\n";
  ITEST_ASSERT_OK_AND_ASSIGN(plan, GetPlan(stubs, created.job().job_id()));
  ASSERT_GT(plan.sites_size(), 100);
  double worst = 0.0;
  for (const pb::PlanSite& site : plan.sites()) worst = std::max(worst, OffCadBox(BoxPoint(site.position())));
  EXPECT_LT(worst, 1e-6);

  // A rig's command: on a face, with the face's normal away from its edges.
  ITEST_ASSERT_OK_AND_ASSIGN(command, LeaseOne(stubs, created.job().job_id(), "arm"));
  const Eigen::Vector3d p = BoxPoint(command.position()), n = BoxPoint(command.normal());
  EXPECT_LT(OffCadBox(p), 1e-6);
  EXPECT_NEAR(n.norm(), 1.0, 1e-9);
  if (FromCadBoxEdge(p) > 2.0) {
    int axis = 0;
    p.cwiseAbs().maxCoeff(&axis);
    EXPECT_NEAR(n[axis], p[axis] > 0 ? 1.0 : -1.0, 1e-9) << "at " << p.transpose();
  }
  EXPECT_NEAR(BoxPoint(command.drag_direction()).dot(n), 0.0, 1e-9);  // the drag runs along the face

  // A surface the API does not know is refused, naming the field.
  pb::UploadObjectRequest bad;
  bad.set_name("bad");
  bad.set_format(pb::MESH_FORMAT_OBJ);
  bad.set_mesh(WriteObj(MakeCadBox(kHalf)));
  bad.set_surface(static_cast<pb::ObjectSurface>(7));
  pb::UploadObjectResponse refused;
  status = stubs.objects->UploadObject(Context().get(), bad, &refused);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_NE(status.error_message().find("surface"), std::string::npos) << status.error_message();
}

// The same box exported finely (2.5 mm facets, 37,000 triangles, binary STL
// in metres): finer than the 13 mm site spacing, so it is simplified to a
// control mesh. meshoptimizer alone left zero-area triangles along the
// box's edges and CreateJob refused it; the box is now coarsened to its
// corners and refined flat, as a control mesh or as facets.
TEST(CadMesh, AFinelyTessellatedBoxGetsAJobEitherWay) {
  ITEST_ASSERT_OK_AND_ASSIGN(server, ServerProcess::Start());
  Stubs stubs(server->channel());
  for (pb::ObjectSurface surface : {pb::OBJECT_SURFACE_CONTROL_MESH, pb::OBJECT_SURFACE_FACETS}) {
    SCOPED_TRACE(pb::ObjectSurface_Name(surface));
    ITEST_ASSERT_OK_AND_ASSIGN(box, UploadBox(stubs, surface, 2.5));
    EXPECT_GT(box.object().control_vertex_count(), 18000);
    pb::CreateJobRequest create;
    create.mutable_spec()->set_object_id(box.object().object_id());
    create.mutable_spec()->set_property(pb::PROPERTY_FRICTION);
    pb::CreateJobResponse created;
    grpc::Status status = stubs.jobs->CreateJob(Context(120).get(), create, &created);
    ASSERT_TRUE(status.ok()) << status.error_message();
    const double target = 6 * 100.0 * 100.0 / (13.0 * 13.0);
    EXPECT_GT(created.estimate().level0_sites(), 0.65 * target);
    EXPECT_LT(created.estimate().level0_sites(), 1.35 * target);
    ITEST_ASSERT_OK_AND_ASSIGN(plan, GetPlan(stubs, created.job().job_id()));
    double worst = 0.0;
    for (const pb::PlanSite& site : plan.sites()) worst = std::max(worst, OffCadBox(BoxPoint(site.position())));
    EXPECT_LT(worst, 1e-3);  // on the stored float facets (rounded to ~4e-6 mm)
    std::cout << "fine CAD box as " << pb::ObjectSurface_Name(surface) << ": " << created.estimate().level0_sites()
              << " level-0 sites (area / spacing^2 = " << target << "), up to " << worst << " mm off the box\n";
  }
}

}  // namespace
}  // namespace surfmap::itest
