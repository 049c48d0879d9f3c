// Table-driven bad input over the real RPCs: every case must come back with
// the right status code, a message that names the problem, and leave the
// database exactly as it was (row counts per table and command/job states,
// read from the SQLite file directly).
#include <cmath>
#include <functional>
#include <iostream>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "absl/strings/ascii.h"
#include "absl/strings/str_join.h"
#include "clients/remote/remote_call.h"
#include "gtest/gtest.h"
#include "tests/support/db_snapshot.h"
#include "tests/support/job_helpers.h"
#include "tests/support/server_process.h"
#include "tests/support/status_matchers.h"

namespace surfmap::itest {
namespace {

constexpr int kMaxTraceSamples = 5000;

// A small message limit (2 MiB) keeps the oversized case cheap; the trace
// sample limit is lowered so "too many samples" fits under it.
const char* kConfig = R"({"max_message_mb": 2, "max_trace_samples": 5000})";

struct Expectation {
  grpc::StatusCode code;
  std::vector<std::string> any_of;  // the message names the problem: one of these words (case-insensitive)
};

class BadInputTest : public ::testing::Test {
 protected:
  void SetUp() override {
    ServerOptions options;
    options.config_json = kConfig;
    auto server = ServerProcess::Start(options);
    ASSERT_TRUE(server.ok()) << server.status();
    server_ = std::move(*server);
    stubs_ = std::make_unique<Stubs>(server_->channel());
    auto rig = MakeSceneRig("bottle");
    ASSERT_TRUE(rig.ok()) << rig.status();
    rig_ = std::move(*rig);
    auto object = UploadSceneMesh(*stubs_, *rig_);
    ASSERT_TRUE(object.ok()) << object.status();
    object_id_ = object->object_id();
    JobSpecOptions spec;
    spec.mode = pb::SAMPLING_MODE_UNIFORM;
    spec.coarsest_level = 0;
    spec.finest_level = 0;
    auto job = CreateJob(*stubs_, MakeJobSpec(object_id_, spec));
    ASSERT_TRUE(job.ok()) << job.status();
    job_id_ = job->job_id();
    auto command = LeaseOne(*stubs_, job_id_, "rig-bad");
    ASSERT_TRUE(command.ok()) << command.status();
    command_ = *command;
    auto submit = ExecuteOnRig(*rig_, command_, "rig-bad");
    ASSERT_TRUE(submit.ok()) << submit.status();
    good_trace_ = submit->samples();
  }

  // Runs `call`, checks the code and message, and that the DB did not change.
  void Check(const std::string& name, const Expectation& expected, const std::function<grpc::Status()>& call) {
    SCOPED_TRACE(name);
    auto before = TakeDbSnapshot(server_->db_path());
    ASSERT_TRUE(before.ok()) << before.status();
    grpc::Status status = call();
    std::cout << "  " << name << " -> " << Describe(status).substr(0, 160) << "\n";
    EXPECT_EQ(status.error_code(), expected.code)
        << name << ": expected " << cli::StatusCodeName(expected.code) << ", got " << Describe(status);
    EXPECT_TRUE(MessageNames(status.error_message(), expected.any_of))
        << name << ": the message should name the problem (one of: " << absl::StrJoin(expected.any_of, ", ")
        << "), got: " << Describe(status);
    auto after = TakeDbSnapshot(server_->db_path());
    ASSERT_TRUE(after.ok()) << after.status();
    const std::string difference = before->DifferenceTo(*after);
    EXPECT_TRUE(difference.empty()) << name << " changed the database: " << difference;
    ++checked_;
  }

  grpc::Status Submit(const pb::TraceSamples& samples, int64_t command_id, const std::string& rig_id = "rig-bad") {
    pb::SubmitTraceRequest request;
    request.set_command_id(command_id);
    request.set_rig_id(rig_id);
    *request.mutable_samples() = samples;
    pb::SubmitTraceResponse response;
    return stubs_->probe->SubmitTrace(Context().get(), request, &response);
  }

  grpc::Status Upload(const std::string& bytes, pb::MeshFormat format, const std::string& name = "broken") {
    pb::UploadObjectRequest request;
    request.set_name(name);
    request.set_format(format);
    request.set_mesh(bytes);
    pb::UploadObjectResponse response;
    return stubs_->objects->UploadObject(Context().get(), request, &response);
  }

  grpc::Status Create(const std::function<void(pb::JobSpec*)>& edit) {
    JobSpecOptions options;
    options.mode = pb::SAMPLING_MODE_UNIFORM;
    options.finest_level = 0;
    pb::CreateJobRequest request;
    *request.mutable_spec() = MakeJobSpec(object_id_, options);
    edit(request.mutable_spec());
    pb::CreateJobResponse response;
    return stubs_->jobs->CreateJob(Context().get(), request, &response);
  }

  std::unique_ptr<ServerProcess> server_;
  std::unique_ptr<Stubs> stubs_;
  std::unique_ptr<SimulatedRig> rig_;
  int64_t object_id_ = 0;
  int64_t job_id_ = 0;
  pb::ProbeCommand command_;
  pb::TraceSamples good_trace_;
  int checked_ = 0;
};

// Indices of the samples of one phase.
std::vector<int> PhaseIndices(const pb::TraceSamples& s, pb::Phase phase) {
  std::vector<int> out;
  for (int i = 0; i < s.phases_size(); ++i) {
    if (s.phases(i) == phase) out.push_back(i);
  }
  return out;
}

pb::TraceSamples KeepRows(const pb::TraceSamples& s, const std::vector<int>& rows) {
  pb::TraceSamples out;
  for (int i : rows) {
    out.add_t(s.t(i));
    out.add_x(s.x(i));
    out.add_y(s.y(i));
    out.add_z(s.z(i));
    out.add_fx(s.fx(i));
    out.add_fy(s.fy(i));
    out.add_fz(s.fz(i));
    out.add_phases(s.phases(i));
  }
  return out;
}

// `rows` samples: the good trace repeated, time shifted so it keeps increasing.
pb::TraceSamples Tiled(const pb::TraceSamples& s, int rows) {
  pb::TraceSamples out;
  const double period = s.t(s.t_size() - 1) - s.t(0) + 0.01;
  for (int r = 0; r < rows; ++r) {
    const int i = r % s.t_size();
    out.add_t(s.t(i) + period * (r / s.t_size()));
    out.add_x(s.x(i));
    out.add_y(s.y(i));
    out.add_z(s.z(i));
    out.add_fx(s.fx(i));
    out.add_fy(s.fy(i));
    out.add_fz(s.fz(i));
    out.add_phases(s.phases(i));
  }
  return out;
}

TEST_F(BadInputTest, MalformedTracesAreRejectedAndStoreNothing) {
  const int64_t id = command_.command_id();
  const pb::TraceSamples& good = good_trace_;
  ASSERT_GT(good.t_size(), 100);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  using C = grpc::StatusCode;

  struct Case {
    std::string name;
    std::function<pb::TraceSamples()> make;
    Expectation expected;
  };
  const std::vector<Case> cases = {
      {"mismatched column lengths",
       [&] {
         pb::TraceSamples s = good;
         s.mutable_fy()->RemoveLast();
         return s;
       },
       {C::INVALID_ARGUMENT, {"fy", "column", "length"}}},
      {"NaN force",
       [&] {
         pb::TraceSamples s = good;
         s.set_fx(40, nan);
         return s;
       },
       {C::INVALID_ARGUMENT, {"nan", "finite"}}},
      {"infinite position",
       [&] {
         pb::TraceSamples s = good;
         s.set_z(60, std::numeric_limits<double>::infinity());
         return s;
       },
       {C::INVALID_ARGUMENT, {"inf", "finite"}}},
      {"no reverse pass",
       [&] {
         std::vector<int> rows = PhaseIndices(good, pb::PHASE_FORWARD);
         for (int i : PhaseIndices(good, pb::PHASE_PAUSE)) rows.push_back(i);
         return KeepRows(good, rows);
       },
       {C::INVALID_ARGUMENT, {"reverse"}}},
      {"too few samples",
       [&] {
         std::vector<int> fwd = PhaseIndices(good, pb::PHASE_FORWARD), rev = PhaseIndices(good, pb::PHASE_REVERSE);
         return KeepRows(good, {fwd[0], fwd[1], fwd[2], fwd[3], rev[rev.size() - 4], rev[rev.size() - 3],
                                rev[rev.size() - 2], rev[rev.size() - 1]});
       },
       {C::INVALID_ARGUMENT, {"few", "samples"}}},
      {"reverse pass does not retrace the forward pass",
       [&] {
         // Move the reverse pass 6 mm sideways (perpendicular to the drag
         // and the normal): the two passes no longer pair.
         pb::TraceSamples s = good;
         Eigen::Vector3d n(command_.normal().x(), command_.normal().y(), command_.normal().z());
         Eigen::Vector3d d(command_.drag_direction().x(), command_.drag_direction().y(),
                           command_.drag_direction().z());
         Eigen::Vector3d side = n.cross(d).normalized() * 6.0;
         for (int i : PhaseIndices(good, pb::PHASE_REVERSE)) {
           s.set_x(i, s.x(i) + side.x());
           s.set_y(i, s.y(i) + side.y());
           s.set_z(i, s.z(i) + side.z());
         }
         return s;
       },
       {C::INVALID_ARGUMENT, {"retrace", "reverse"}}},
      {"time not increasing",
       [&] {
         pb::TraceSamples s = good;
         s.set_t(50, s.t(49));
         return s;
       },
       {C::INVALID_ARGUMENT, {"time", "increas", " t "}}},
      {"phases out of order",
       [&] {
         pb::TraceSamples s = good;
         s.set_phases(5, pb::PHASE_REVERSE);
         return s;
       },
       {C::INVALID_ARGUMENT, {"phase", "order"}}},
      {"UNSPECIFIED phase",
       [&] {
         pb::TraceSamples s = good;
         s.set_phases(10, pb::PHASE_UNSPECIFIED);
         return s;
       },
       {C::INVALID_ARGUMENT, {"phase"}}},
      {"zero force",
       [&] {
         pb::TraceSamples s = good;
         for (int i = 0; i < s.t_size(); ++i) {
           s.set_fx(i, 0);
           s.set_fy(i, 0);
           s.set_fz(i, 0);
         }
         return s;
       },
       {C::INVALID_ARGUMENT, {"force"}}},
      {"no samples", [&] { return pb::TraceSamples(); }, {C::INVALID_ARGUMENT, {"sample", "empty"}}},
      {"more samples than max_trace_samples", [&] { return Tiled(good, kMaxTraceSamples + 1); },
       {C::RESOURCE_EXHAUSTED, {"samples", "limit", "5000"}}},
      {"message over the size limit (3 MB > 2 MiB)", [&] { return Tiled(good, 48'000); },
       {C::RESOURCE_EXHAUSTED, {"larger", "max", "size", "limit"}}},
  };
  for (const Case& c : cases) Check("SubmitTrace: " + c.name, c.expected, [&] { return Submit(c.make(), id); });

  Check("SubmitTrace: command id 0", {C::INVALID_ARGUMENT, {"command"}}, [&] { return Submit(good, 0); });
  Check("SubmitTrace: unknown command id", {C::NOT_FOUND, {"987654"}}, [&] { return Submit(good, 987654); });
  Check("SubmitTrace: empty rig id", {C::INVALID_ARGUMENT, {"rig"}}, [&] { return Submit(good, id, ""); });
  Check("SubmitTrace: rig id over 100 characters", {C::INVALID_ARGUMENT, {"rig"}},
        [&] { return Submit(good, id, std::string(101, 'r')); });

  // The command survived all of that: the good trace is accepted.
  pb::SubmitTraceRequest request;
  request.set_command_id(id);
  request.set_rig_id("rig-bad");
  *request.mutable_samples() = good;
  pb::SubmitTraceResponse response;
  GRPC_EXPECT_OK(stubs_->probe->SubmitTrace(Context().get(), request, &response));
  EXPECT_FALSE(response.already_accepted());
  EXPECT_GT(response.sample().trace_id(), 0);
  EXPECT_NEAR(response.sample().fit().friction().mu(), 0.13, 0.06) << "glass or sandpaper: " << response.ShortDebugString().substr(0, 400);
}

TEST_F(BadInputTest, UnknownIdsUnspecifiedEnumsAndBadFields) {
  using C = grpc::StatusCode;
  const int64_t unknown = 424242;

  Check("GetObject: unknown id", {C::NOT_FOUND, {"424242"}}, [&] {
    pb::GetObjectRequest r;
    r.set_object_id(unknown);
    pb::GetObjectResponse out;
    return stubs_->objects->GetObject(Context().get(), r, &out);
  });
  Check("GetMesh: unknown object", {C::NOT_FOUND, {"424242"}}, [&] {
    pb::GetMeshRequest r;
    r.set_object_id(unknown);
    pb::GetMeshResponse out;
    return stubs_->objects->GetMesh(Context().get(), r, &out);
  });
  Check("GetMesh: level 7", {C::INVALID_ARGUMENT, {"level"}}, [&] {
    pb::GetMeshRequest r;
    r.set_object_id(object_id_);
    r.set_level(7);
    pb::GetMeshResponse out;
    return stubs_->objects->GetMesh(Context().get(), r, &out);
  });
  Check("GetJob: unknown id", {C::NOT_FOUND, {"424242"}}, [&] {
    pb::GetJobRequest r;
    r.set_job_id(unknown);
    pb::GetJobResponse out;
    return stubs_->jobs->GetJob(Context().get(), r, &out);
  });
  Check("GetPlan: unknown job", {C::NOT_FOUND, {"424242"}}, [&] {
    pb::GetPlanRequest r;
    r.set_job_id(unknown);
    pb::GetPlanResponse out;
    return stubs_->jobs->GetPlan(Context().get(), r, &out);
  });
  Check("PauseJob: unknown job", {C::NOT_FOUND, {"424242"}}, [&] {
    pb::SetJobStateRequest r;
    r.set_job_id(unknown);
    pb::SetJobStateResponse out;
    return stubs_->jobs->PauseJob(Context().get(), r, &out);
  });
  Check("CancelJob: unknown job", {C::NOT_FOUND, {"424242"}}, [&] {
    pb::SetJobStateRequest r;
    r.set_job_id(unknown);
    pb::SetJobStateResponse out;
    return stubs_->jobs->CancelJob(Context().get(), r, &out);
  });
  Check("GetTrace: unknown id", {C::NOT_FOUND, {"424242"}}, [&] {
    pb::GetTraceRequest r;
    r.set_trace_id(unknown);
    pb::GetTraceResponse out;
    return stubs_->traces->GetTrace(Context().get(), r, &out);
  });
  Check("GetSample: unknown trace", {C::NOT_FOUND, {"424242"}}, [&] {
    pb::GetSampleRequest r;
    r.set_trace_id(unknown);
    pb::GetSampleResponse out;
    return stubs_->maps->GetSample(Context().get(), r, &out);
  });
  Check("GetMap: unknown job", {C::NOT_FOUND, {"424242"}}, [&] {
    pb::GetMapRequest r;
    r.set_job_id(unknown);
    r.set_level(-1);
    pb::GetMapResponse out;
    return stubs_->maps->GetMap(Context().get(), r, &out);
  });
  Check("GetMap: level 9", {C::INVALID_ARGUMENT, {"level"}}, [&] {
    pb::GetMapRequest r;
    r.set_job_id(job_id_);
    r.set_level(9);
    pb::GetMapResponse out;
    return stubs_->maps->GetMap(Context().get(), r, &out);
  });
  Check("QueryMap: unknown job", {C::NOT_FOUND, {"424242"}}, [&] {
    pb::QueryMapRequest r;
    r.set_job_id(unknown);
    r.add_points()->set_z(10);
    pb::QueryMapResponse out;
    return stubs_->maps->QueryMap(Context().get(), r, &out);
  });
  Check("QueryMap: 10,001 points", {C::RESOURCE_EXHAUSTED, {"10000", "10,000", "points"}}, [&] {
    pb::QueryMapRequest r;
    r.set_job_id(job_id_);
    for (int i = 0; i < 10'001; ++i) r.add_points()->set_z(i * 0.01);
    pb::QueryMapResponse out;
    return stubs_->maps->QueryMap(Context().get(), r, &out);
  });
  Check("QueryMap: NaN point", {C::INVALID_ARGUMENT, {"nan", "finite", "point"}}, [&] {
    pb::QueryMapRequest r;
    r.set_job_id(job_id_);
    r.add_points()->set_x(std::nan(""));
    pb::QueryMapResponse out;
    return stubs_->maps->QueryMap(Context().get(), r, &out);
  });
  Check("LeaseCommand: unknown job", {C::NOT_FOUND, {"424242"}}, [&] {
    pb::LeaseCommandRequest r;
    r.set_rig_id("rig-x");
    r.set_job_id(unknown);
    pb::LeaseCommandResponse out;
    return stubs_->probe->LeaseCommand(Context().get(), r, &out);
  });
  Check("LeaseCommand: empty rig id", {C::INVALID_ARGUMENT, {"rig"}}, [&] {
    pb::LeaseCommandRequest r;
    r.set_job_id(job_id_);
    pb::LeaseCommandResponse out;
    return stubs_->probe->LeaseCommand(Context().get(), r, &out);
  });
  Check("ReportFailure: unknown command", {C::NOT_FOUND, {"424242"}}, [&] {
    pb::ReportFailureRequest r;
    r.set_command_id(unknown);
    r.set_rig_id("rig-x");
    r.set_reason("test");
    pb::ReportFailureResponse out;
    return stubs_->probe->ReportFailure(Context().get(), r, &out);
  });
  Check("RefitJob: unknown job", {C::NOT_FOUND, {"424242"}}, [&] {
    pb::RefitJobRequest r;
    r.set_job_id(unknown);
    r.mutable_settings()->set_ar_method(pb::AR_METHOD_BURG);
    pb::RefitJobResponse out;
    return stubs_->traces->RefitJob(Context().get(), r, &out);
  });
  Check("RefitJob: UNSPECIFIED ar_method", {C::INVALID_ARGUMENT, {"ar_method"}}, [&] {
    pb::RefitJobRequest r;
    r.set_job_id(job_id_);
    pb::RefitJobResponse out;
    return stubs_->traces->RefitJob(Context().get(), r, &out);
  });
  Check("RefitJob: negative step", {C::INVALID_ARGUMENT, {"step"}}, [&] {
    pb::RefitJobRequest r;
    r.set_job_id(job_id_);
    r.mutable_settings()->set_ar_method(pb::AR_METHOD_BURG);
    r.mutable_settings()->set_step_mm(-0.1);
    pb::RefitJobResponse out;
    return stubs_->traces->RefitJob(Context().get(), r, &out);
  });

  Check("CreateJob: unknown object", {C::NOT_FOUND, {"424242"}},
        [&] { return Create([&](pb::JobSpec* s) { s->set_object_id(unknown); }); });
  Check("CreateJob: object id 0", {C::INVALID_ARGUMENT, {"object"}},
        [&] { return Create([&](pb::JobSpec* s) { s->set_object_id(0); }); });
  Check("CreateJob: UNSPECIFIED property", {C::INVALID_ARGUMENT, {"property"}},
        [&] { return Create([&](pb::JobSpec* s) { s->set_property(pb::PROPERTY_UNSPECIFIED); }); });
  Check("CreateJob: unknown property value 42", {C::INVALID_ARGUMENT, {"property"}},
        [&] { return Create([&](pb::JobSpec* s) { s->set_property(static_cast<pb::Property>(42)); }); });
  Check("CreateJob: unknown mode value 42", {C::INVALID_ARGUMENT, {"mode"}},
        [&] { return Create([&](pb::JobSpec* s) { s->set_mode(static_cast<pb::SamplingMode>(42)); }); });
  Check("CreateJob: a threshold in a mode that does not read it", {C::INVALID_ARGUMENT, {"threshold", "ADAPTIVE"}},
        [&] {
          return Create([&](pb::JobSpec* s) {
            s->set_mode(pb::SAMPLING_MODE_BOUNDARY);
            s->set_threshold(3.0);
          });
        });
  Check("CreateJob: map level below the finest level", {C::INVALID_ARGUMENT, {"map_level"}}, [&] {
    return Create([&](pb::JobSpec* s) {
      s->set_finest_level(2);
      s->set_map_level(1);
    });
  });
  Check("CreateJob: an approach cone of 0 degrees", {C::INVALID_ARGUMENT, {"reach"}}, [&] {
    return Create([&](pb::JobSpec* s) {
      s->mutable_reach()->mutable_approach_direction()->set_z(1.0);
      s->mutable_reach()->set_max_angle_deg(-5.0);
    });
  });
  Check("CreateJob: finest level below coarsest", {C::INVALID_ARGUMENT, {"level"}}, [&] {
    return Create([&](pb::JobSpec* s) {
      s->set_coarsest_level(2);
      s->set_finest_level(1);
    });
  });
  Check("CreateJob: finest level 9", {C::INVALID_ARGUMENT, {"level"}},
        [&] { return Create([&](pb::JobSpec* s) { s->set_finest_level(9); }); });
  Check("CreateJob: negative budget", {C::INVALID_ARGUMENT, {"budget"}},
        [&] { return Create([&](pb::JobSpec* s) { s->set_budget(-5); }); });
  Check("CreateJob: NaN threshold", {C::INVALID_ARGUMENT, {"threshold"}},
        [&] { return Create([&](pb::JobSpec* s) { s->set_threshold(std::nan("")); }); });
  Check("CreateJob: uncertainty mode without a budget", {C::INVALID_ARGUMENT, {"budget"}}, [&] {
    return Create([&](pb::JobSpec* s) {
      s->set_mode(pb::SAMPLING_MODE_UNCERTAINTY);
      s->set_finest_level(1);
      s->set_budget(0);
    });
  });
  Check("CreateJob: negative speed", {C::INVALID_ARGUMENT, {"speed"}},
        [&] { return Create([&](pb::JobSpec* s) { s->mutable_probe()->set_speed_mm_s(-10); }); });
  Check("CreateJob: negative lease", {C::INVALID_ARGUMENT, {"lease"}},
        [&] { return Create([&](pb::JobSpec* s) { s->mutable_lease()->set_seconds(-1); }); });
  EXPECT_GE(checked_, 30);
}

TEST_F(BadInputTest, BrokenMeshesAreRejectedAndStoreNothing) {
  using C = grpc::StatusCode;
  const std::string tetra = "v 0 0 0\nv 10 0 0\nv 0 10 0\nv 0 0 10\nf 1 3 2\nf 1 2 4\nf 2 3 4\nf 1 4 3\n";
  ITEST_ASSERT_OK_AND_ASSIGN(tetra_ok, [&]() -> absl::StatusOr<bool> {
    grpc::Status s = Upload(tetra, pb::MESH_FORMAT_OBJ, "tetrahedron");
    if (!s.ok()) return FromGrpc(s, "UploadObject(valid tetrahedron)");
    return true;
  }());
  (void)tetra_ok;

  // Three triangles on the edge 1-2.
  const std::string non_manifold =
      "v 0 0 0\nv 10 0 0\nv 0 10 0\nv 0 -10 0\nv 0 0 10\nf 1 2 3\nf 2 1 4\nf 1 2 5\n";
  Check("UploadObject: non-manifold edge", {C::INVALID_ARGUMENT, {"manifold"}},
        [&] { return Upload(non_manifold, pb::MESH_FORMAT_OBJ); });
  Check("UploadObject: NaN coordinate", {C::INVALID_ARGUMENT, {"nan", "finite"}}, [&] {
    return Upload("v 0 0 0\nv 10 nan 0\nv 0 10 0\nv 0 0 10\nf 1 3 2\nf 1 2 4\nf 2 3 4\nf 1 4 3\n",
                  pb::MESH_FORMAT_OBJ);
  });
  Check("UploadObject: face index out of range", {C::INVALID_ARGUMENT, {"range", "index", "9"}}, [&] {
    return Upload("v 0 0 0\nv 10 0 0\nv 0 10 0\nv 0 0 10\nf 1 3 2\nf 1 2 9\nf 2 3 4\nf 1 4 3\n",
                  pb::MESH_FORMAT_OBJ);
  });
  Check("UploadObject: empty OBJ", {C::INVALID_ARGUMENT, {"empty", "no "}},
        [&] { return Upload("", pb::MESH_FORMAT_OBJ); });
  Check("UploadObject: empty PLY", {C::INVALID_ARGUMENT, {"empty", "ply", "header"}},
        [&] { return Upload("", pb::MESH_FORMAT_PLY); });
  std::mt19937_64 random(20010521);
  std::string garbage(4096, '\0');
  for (char& c : garbage) c = static_cast<char>(random() & 0xff);
  Check("UploadObject: garbage bytes as OBJ", {C::INVALID_ARGUMENT, {}},
        [&] { return Upload(garbage, pb::MESH_FORMAT_OBJ); });
  Check("UploadObject: garbage bytes as PLY", {C::INVALID_ARGUMENT, {"ply", "header", "magic"}},
        [&] { return Upload(garbage, pb::MESH_FORMAT_PLY); });
  Check("UploadObject: truncated binary PLY", {C::INVALID_ARGUMENT, {"ply", "byte", "end", "truncat"}}, [&] {
    auto bytes = ReadFileBytes(SourcePath("tests/data/meshes/icosahedron_binary_le.ply"));
    EXPECT_TRUE(bytes.ok()) << bytes.status();
    return Upload(bytes.ok() ? bytes->substr(0, bytes->size() - 40) : std::string("ply"), pb::MESH_FORMAT_PLY);
  });
  Check("UploadObject: UNSPECIFIED format", {C::INVALID_ARGUMENT, {"format"}},
        [&] { return Upload(tetra, pb::MESH_FORMAT_UNSPECIFIED); });
  Check("UploadObject: empty name", {C::INVALID_ARGUMENT, {"name"}},
        [&] { return Upload(tetra, pb::MESH_FORMAT_OBJ, ""); });
  Check("UploadObject: name of 201 characters", {C::INVALID_ARGUMENT, {"name"}},
        [&] { return Upload(tetra, pb::MESH_FORMAT_OBJ, std::string(201, 'n')); });
}

TEST_F(BadInputTest, SubmittingToACancelledJobIsAFailedPrecondition) {
  using C = grpc::StatusCode;
  pb::SetJobStateRequest cancel;
  cancel.set_job_id(job_id_);
  pb::SetJobStateResponse cancelled;
  GRPC_ASSERT_OK(stubs_->jobs->CancelJob(Context().get(), cancel, &cancelled));
  EXPECT_EQ(cancelled.job().state(), pb::JOB_STATE_CANCELLED);

  Check("SubmitTrace: job cancelled", {C::FAILED_PRECONDITION, {"cancel"}},
        [&] { return Submit(good_trace_, command_.command_id()); });
  Check("ReportFailure: job cancelled", {C::FAILED_PRECONDITION, {"cancel"}}, [&] {
    pb::ReportFailureRequest r;
    r.set_command_id(command_.command_id());
    r.set_rig_id("rig-bad");
    r.set_reason("test");
    pb::ReportFailureResponse out;
    return stubs_->probe->ReportFailure(Context().get(), r, &out);
  });
  Check("ResumeJob: cancelled", {C::FAILED_PRECONDITION, {"cancel"}}, [&] {
    pb::SetJobStateResponse out;
    return stubs_->jobs->ResumeJob(Context().get(), cancel, &out);
  });
  Check("PauseJob: cancelled", {C::FAILED_PRECONDITION, {"cancel"}}, [&] {
    pb::SetJobStateResponse out;
    return stubs_->jobs->PauseJob(Context().get(), cancel, &out);
  });
}

}  // namespace
}  // namespace surfmap::itest
