// Small blocking wrappers over the surfmap.v1 RPCs that tests repeat: scene
// rigs, uploads, job creation, plan/map reads, waiting for a job state.
// RPC failures come back as absl statuses whose message starts with the RPC
// name and the gRPC code ("GetJob(7): NOT_FOUND: ...").
#pragma once

#include <chrono>
#include <cstdint>
#include <memory>
#include <string>

#include "absl/status/statusor.h"
#include "clients/sim/rig/simulated_rig.h"
#include "tests/support/server_process.h"
#include "tests/support/surfmap_client.h"

namespace surfmap::itest {

absl::Status FromGrpc(const grpc::Status& status, const std::string& call);

// A SimulatedRig on built-in scene `scene` ("bottle", "plate").
absl::StatusOr<std::unique_ptr<SimulatedRig>> MakeSceneRig(const std::string& scene);

// Uploads the rig scene's own control mesh (as OBJ), so the server's surface
// and the rig's are the same object.
absl::StatusOr<pb::ObjectInfo> UploadSceneMesh(Stubs& stubs, const SimulatedRig& rig, const std::string& token = "");

// A fresh server (ServerProcess::Start()) with a scene's mesh uploaded, its
// rig, and stubs on the server's channel.
struct SceneServer {
  std::unique_ptr<ServerProcess> server;
  std::unique_ptr<SimulatedRig> rig;
  std::unique_ptr<Stubs> stubs;
  std::int64_t object_id = 0;
};
absl::StatusOr<SceneServer> StartServerWithScene(const std::string& scene);

// The simulated rig's trace for `command`, as `rig_id`'s SubmitTrace request.
absl::StatusOr<pb::SubmitTraceRequest> ExecuteOnRig(const SimulatedRig& rig, const pb::ProbeCommand& command,
                                                    const std::string& rig_id);

struct JobSpecOptions {
  pb::Property property = pb::PROPERTY_FRICTION;
  pb::SamplingMode mode = pb::SAMPLING_MODE_ADAPTIVE;
  int coarsest_level = 0;
  int finest_level = 1;
  double threshold = 2.0;
  int budget = 0;
  std::uint64_t seed = 7;
  double lease_s = 0.0;   // 0 = server default
  int max_retries = 0;    // 0 = server default
};
pb::JobSpec MakeJobSpec(std::int64_t object_id, const JobSpecOptions& options = {});
// A uniform job over the level-0 sites (budget 0 = all; lease_s 0 = server default).
pb::JobSpec UniformLevel0Spec(std::int64_t object_id, int budget = 0, double lease_s = 0.0);

absl::StatusOr<pb::JobInfo> CreateJob(Stubs& stubs, const pb::JobSpec& spec, const std::string& token = "");
absl::StatusOr<pb::JobInfo> GetJob(Stubs& stubs, std::int64_t job_id);
absl::StatusOr<pb::GetPlanResponse> GetPlan(Stubs& stubs, std::int64_t job_id);
absl::StatusOr<pb::GetMapResponse> GetMap(Stubs& stubs, std::int64_t job_id, int level, bool include_mesh);
absl::StatusOr<pb::ListSamplesResponse> ListSamples(Stubs& stubs, std::int64_t job_id);

// Polls GetJob until the job is in `state` (DEADLINE_EXCEEDED naming the last
// state seen otherwise).
absl::StatusOr<pb::JobInfo> WaitForJobState(Stubs& stubs, std::int64_t job_id, pb::JobState state,
                                            std::chrono::milliseconds timeout);

// Leases one command for `rig_id` from `job_id`, polling while none is ready
// (up to `timeout`). NOT_FOUND-like outcomes (job_finished) are
// FAILED_PRECONDITION.
absl::StatusOr<pb::ProbeCommand> LeaseOne(Stubs& stubs, std::int64_t job_id, const std::string& rig_id,
                                          std::chrono::milliseconds timeout = std::chrono::seconds(30));

}  // namespace surfmap::itest
