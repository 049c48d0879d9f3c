#include "tests/support/job_helpers.h"

#include <thread>

#include "server/codec/trace_samples_proto.h"
#include "absl/strings/str_cat.h"
#include "clients/sim/rig/scene.h"
#include "server/mesh/control_mesh.h"

namespace surfmap::itest {

using Clock = std::chrono::steady_clock;

absl::Status FromGrpc(const grpc::Status& status, const std::string& call) {
  if (status.ok()) return absl::OkStatus();
  return absl::Status(static_cast<absl::StatusCode>(status.error_code()),
                      absl::StrCat(call, ": ", Describe(status)));
}

absl::StatusOr<std::unique_ptr<SimulatedRig>> MakeSceneRig(const std::string& scene_name) {
  absl::StatusOr<Scene> scene = LoadSceneByName(scene_name);
  if (!scene.ok()) return scene.status();
  absl::StatusOr<std::unique_ptr<SimulatedRig>> rig = SimulatedRig::Create(std::move(*scene));
  if (!rig.ok()) return rig.status();
  return std::move(*rig);
}

absl::StatusOr<pb::ObjectInfo> UploadSceneMesh(Stubs& stubs, const SimulatedRig& rig, const std::string& token) {
  pb::UploadObjectRequest request;
  request.set_name(rig.scene().name);
  request.set_format(pb::MESH_FORMAT_OBJ);
  request.set_mesh(WriteObj(rig.scene().mesh));
  pb::UploadObjectResponse response;
  grpc::Status status = stubs.objects->UploadObject(Context(120, token).get(), request, &response);
  if (!status.ok()) return FromGrpc(status, "UploadObject(" + rig.scene().name + ")");
  return response.object();
}

absl::StatusOr<SceneServer> StartServerWithScene(const std::string& scene) {
  SceneServer setup;
  auto server = ServerProcess::Start();
  if (!server.ok()) return server.status();
  setup.server = std::move(*server);
  auto rig = MakeSceneRig(scene);
  if (!rig.ok()) return rig.status();
  setup.rig = std::move(*rig);
  setup.stubs = std::make_unique<Stubs>(setup.server->channel());
  auto object = UploadSceneMesh(*setup.stubs, *setup.rig);
  if (!object.ok()) return object.status();
  setup.object_id = object->object_id();
  return setup;
}

absl::StatusOr<pb::SubmitTraceRequest> ExecuteOnRig(const SimulatedRig& rig, const pb::ProbeCommand& command,
                                                    const std::string& rig_id) {
  absl::StatusOr<ProbeRequest> probe = SeededProbeRequest(command, command.command_id());
  if (!probe.ok()) return probe.status();
  absl::StatusOr<ProbeExecution> execution = rig.ExecuteDetailed(*probe);
  if (!execution.ok()) return execution.status();
  pb::SubmitTraceRequest request;
  request.set_command_id(command.command_id());
  request.set_rig_id(rig_id);
  *request.mutable_samples() = DragTraceToProto(execution->trace);
  return request;
}

pb::JobSpec UniformLevel0Spec(std::int64_t object_id, int budget, double lease_s) {
  JobSpecOptions spec;
  spec.mode = pb::SAMPLING_MODE_UNIFORM;
  spec.finest_level = 0;
  spec.budget = budget;
  spec.lease_s = lease_s;
  return MakeJobSpec(object_id, spec);
}

pb::JobSpec MakeJobSpec(std::int64_t object_id, const JobSpecOptions& options) {
  pb::JobSpec spec;
  spec.set_object_id(object_id);
  spec.set_property(options.property);
  spec.set_mode(options.mode);
  spec.set_coarsest_level(options.coarsest_level);
  spec.set_finest_level(options.finest_level);
  if (options.mode == pb::SAMPLING_MODE_ADAPTIVE) spec.set_threshold(options.threshold);  // read only there
  spec.set_budget(options.budget);
  spec.set_seed(options.seed);
  spec.mutable_probe()->set_segment_length_mm(20.0);
  spec.mutable_probe()->set_speed_mm_s(10.0);
  spec.mutable_probe()->set_normal_force_n(5.0);
  if (options.max_retries > 0) spec.set_max_retries(options.max_retries);
  if (options.lease_s > 0) {
    const int64_t nanos = static_cast<int64_t>(options.lease_s * 1e9);
    spec.mutable_lease()->set_seconds(nanos / 1'000'000'000);
    spec.mutable_lease()->set_nanos(static_cast<int32_t>(nanos % 1'000'000'000));
  }
  return spec;
}

absl::StatusOr<pb::JobInfo> CreateJob(Stubs& stubs, const pb::JobSpec& spec, const std::string& token) {
  pb::CreateJobRequest request;
  *request.mutable_spec() = spec;
  pb::CreateJobResponse response;
  grpc::Status status = stubs.jobs->CreateJob(Context(120, token).get(), request, &response);
  if (!status.ok()) return FromGrpc(status, "CreateJob");
  return response.job();
}

absl::StatusOr<pb::JobInfo> GetJob(Stubs& stubs, std::int64_t job_id) {
  pb::GetJobRequest request;
  request.set_job_id(job_id);
  pb::GetJobResponse response;
  grpc::Status status = stubs.jobs->GetJob(Context().get(), request, &response);
  if (!status.ok()) return FromGrpc(status, absl::StrCat("GetJob(", job_id, ")"));
  return response.job();
}

absl::StatusOr<pb::GetPlanResponse> GetPlan(Stubs& stubs, std::int64_t job_id) {
  pb::GetPlanRequest request;
  request.set_job_id(job_id);
  pb::GetPlanResponse response;
  grpc::Status status = stubs.jobs->GetPlan(Context().get(), request, &response);
  if (!status.ok()) return FromGrpc(status, absl::StrCat("GetPlan(", job_id, ")"));
  return response;
}

absl::StatusOr<pb::GetMapResponse> GetMap(Stubs& stubs, std::int64_t job_id, int level, bool include_mesh) {
  pb::GetMapRequest request;
  request.set_job_id(job_id);
  request.set_level(level);
  request.set_include_mesh(include_mesh);
  pb::GetMapResponse response;
  grpc::Status status = stubs.maps->GetMap(Context(120).get(), request, &response);
  if (!status.ok()) return FromGrpc(status, absl::StrCat("GetMap(", job_id, ", level ", level, ")"));
  return response;
}

absl::StatusOr<pb::ListSamplesResponse> ListSamples(Stubs& stubs, std::int64_t job_id) {
  pb::ListSamplesRequest request;
  request.set_job_id(job_id);
  pb::ListSamplesResponse response;
  grpc::Status status = stubs.maps->ListSamples(Context().get(), request, &response);
  if (!status.ok()) return FromGrpc(status, absl::StrCat("ListSamples(", job_id, ")"));
  return response;
}

absl::StatusOr<pb::JobInfo> WaitForJobState(Stubs& stubs, std::int64_t job_id, pb::JobState state,
                                            std::chrono::milliseconds timeout) {
  const Clock::time_point deadline = Clock::now() + timeout;
  pb::JobInfo last;
  while (true) {
    absl::StatusOr<pb::JobInfo> job = GetJob(stubs, job_id);
    if (!job.ok()) return job.status();
    if (job->state() == state) return job;
    last = *job;
    if (Clock::now() > deadline) {
      return absl::DeadlineExceededError(absl::StrCat("job ", job_id, " not in state ", pb::JobState_Name(state),
                                                      " after ", timeout.count(), " ms; last: ",
                                                      last.ShortDebugString()));
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
}

absl::StatusOr<pb::ProbeCommand> LeaseOne(Stubs& stubs, std::int64_t job_id, const std::string& rig_id,
                                          std::chrono::milliseconds timeout) {
  const Clock::time_point deadline = Clock::now() + timeout;
  while (true) {
    pb::LeaseCommandRequest request;
    request.set_rig_id(rig_id);
    request.set_job_id(job_id);
    pb::LeaseCommandResponse response;
    grpc::Status status = stubs.probe->LeaseCommand(Context().get(), request, &response);
    if (!status.ok()) return FromGrpc(status, absl::StrCat("LeaseCommand(", rig_id, ", job ", job_id, ")"));
    if (response.job_finished()) {
      return absl::FailedPreconditionError(absl::StrCat("LeaseCommand: job ", job_id, " finished"));
    }
    if (response.has_command() && response.command().command_id() != 0) return response.command();
    if (Clock::now() > deadline) {
      return absl::DeadlineExceededError(absl::StrCat("LeaseCommand: no command for job ", job_id, " within ",
                                                      timeout.count(), " ms"));
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
}

}  // namespace surfmap::itest
