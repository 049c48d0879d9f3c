// Job steering (pause, resume, cancel), the WatchJob stream, the standard
// health and reflection services, and token roles, through the real server.
#include <atomic>
#include <set>
#include <thread>

#include "support/grpc/health/v1/health.grpc.pb.h"
#include "support/grpc/reflection/v1alpha/reflection.grpc.pb.h"
#include "grpc/reflection/v1/reflection.grpc.pb.h"
#include <google/protobuf/descriptor.pb.h>
#include "gtest/gtest.h"
#include "tests/support/job_helpers.h"
#include "tests/support/rig_fleet.h"
#include "tests/support/server_process.h"
#include "tests/support/status_matchers.h"

namespace surfmap::itest {
namespace {

using std::chrono::milliseconds;
using std::chrono::seconds;

pb::LeaseCommandResponse Lease(Stubs& stubs, int64_t job_id, const std::string& rig_id, grpc::Status* status) {
  pb::LeaseCommandRequest request;
  request.set_rig_id(rig_id);
  request.set_job_id(job_id);
  pb::LeaseCommandResponse response;
  *status = stubs.probe->LeaseCommand(Context().get(), request, &response);
  return response;
}

TEST(JobLifecycle, PauseResumeAndCancelGateTheCommands) {
  ITEST_ASSERT_OK_AND_ASSIGN(server, ServerProcess::Start());
  ITEST_ASSERT_OK_AND_ASSIGN(rig, MakeSceneRig("bottle"));
  Stubs stubs(server->channel());
  ITEST_ASSERT_OK_AND_ASSIGN(object, UploadSceneMesh(stubs, *rig));
  JobSpecOptions spec;
  spec.mode = pb::SAMPLING_MODE_UNIFORM;
  spec.finest_level = 0;
  ITEST_ASSERT_OK_AND_ASSIGN(job, CreateJob(stubs, MakeJobSpec(object.object_id(), spec)));
  pb::SetJobStateRequest request;
  request.set_job_id(job.job_id());
  pb::SetJobStateResponse response;

  GRPC_ASSERT_OK(stubs.jobs->PauseJob(Context().get(), request, &response));
  EXPECT_EQ(response.job().state(), pb::JOB_STATE_PAUSED);
  grpc::Status status;
  pb::LeaseCommandResponse lease = Lease(stubs, job.job_id(), "rig-1", &status);
  GRPC_ASSERT_OK(status);
  EXPECT_FALSE(lease.has_command() && lease.command().command_id() != 0) << "a paused job handed out a command";
  EXPECT_FALSE(lease.job_finished()) << "a paused job is not finished";
  EXPECT_TRUE(lease.has_retry_after()) << "a paused job should tell the rig when to ask again";
  // Pausing a paused job is a transition to the state it is in: refused as
  // FAILED_PRECONDITION (IsJobTransitionAllowed: from != to), and the job
  // stays paused.
  grpc::Status again = stubs.jobs->PauseJob(Context().get(), request, &response);
  EXPECT_EQ(again.error_code(), grpc::StatusCode::FAILED_PRECONDITION) << Describe(again);

  GRPC_ASSERT_OK(stubs.jobs->ResumeJob(Context().get(), request, &response));
  EXPECT_EQ(response.job().state(), pb::JOB_STATE_RUNNING);
  lease = Lease(stubs, job.job_id(), "rig-1", &status);
  GRPC_ASSERT_OK(status);
  ASSERT_TRUE(lease.has_command() && lease.command().command_id() != 0) << "a resumed job gives commands";

  GRPC_ASSERT_OK(stubs.jobs->CancelJob(Context().get(), request, &response));
  EXPECT_EQ(response.job().state(), pb::JOB_STATE_CANCELLED);
  lease = Lease(stubs, job.job_id(), "rig-2", &status);
  GRPC_ASSERT_OK(status);
  EXPECT_TRUE(lease.job_finished()) << "rigs must be told to stop on a cancelled job";
  EXPECT_FALSE(lease.has_command() && lease.command().command_id() != 0);
  ITEST_ASSERT_OK_AND_ASSIGN(after, GetJob(stubs, job.job_id()));
  EXPECT_EQ(after.state(), pb::JOB_STATE_CANCELLED);
  status = stubs.jobs->ResumeJob(Context().get(), request, &response);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::FAILED_PRECONDITION) << Describe(status);
}

struct WatchLog {
  std::vector<pb::JobUpdate> updates;
  grpc::Status status;
};

void Watch(Stubs& stubs, int64_t job_id, bool include_map, WatchLog* log, std::atomic<bool>* first_update) {
  pb::WatchJobRequest request;
  request.set_job_id(job_id);
  request.set_include_map(include_map);
  auto context = Context(300);
  auto reader = stubs.jobs->WatchJob(context.get(), request);
  pb::JobUpdate update;
  while (reader->Read(&update)) {
    log->updates.push_back(update);
    first_update->store(true);
  }
  log->status = reader->Finish();
}

TEST(JobLifecycle, WatchStreamsProgressAndEndsWhenTheJobCompletes) {
  ITEST_ASSERT_OK_AND_ASSIGN(server, ServerProcess::Start());
  ITEST_ASSERT_OK_AND_ASSIGN(rig, MakeSceneRig("bottle"));
  Stubs stubs(server->channel());
  ITEST_ASSERT_OK_AND_ASSIGN(object, UploadSceneMesh(stubs, *rig));
  JobSpecOptions spec;
  spec.mode = pb::SAMPLING_MODE_UNIFORM;
  spec.finest_level = 0;
  spec.budget = 30;
  ITEST_ASSERT_OK_AND_ASSIGN(job, CreateJob(stubs, MakeJobSpec(object.object_id(), spec)));

  WatchLog plain, with_map;
  std::atomic<bool> plain_started{false}, map_started{false};
  std::thread plain_watcher([&] { Watch(stubs, job.job_id(), false, &plain, &plain_started); });
  std::thread map_watcher([&] { Watch(stubs, job.job_id(), true, &with_map, &map_started); });
  // Both streams are open (the first update arrives on subscription).
  for (int i = 0; i < 500 && !(plain_started && map_started); ++i) std::this_thread::sleep_for(milliseconds(10));

  RigFleetOptions fleet_options;
  fleet_options.rigs = 2;
  fleet_options.job_id = job.job_id();
  RigFleetRecord record = RigFleet(server->address(), *rig, fleet_options).Run();
  for (const std::string& error : record.rpc_errors) ADD_FAILURE() << error;
  ITEST_ASSERT_OK_AND_ASSIGN(done, WaitForJobState(stubs, job.job_id(), pb::JOB_STATE_COMPLETED, seconds(30)));
  EXPECT_EQ(done.progress().measured(), 30) << "budget 30";

  plain_watcher.join();  // the streams end by themselves when the job completes
  map_watcher.join();
  for (const WatchLog* log : {&plain, &with_map}) {
    EXPECT_TRUE(log->status.ok()) << "the watch stream should end with OK when the job completes: "
                                  << Describe(log->status);
    ASSERT_GE(log->updates.size(), 2u) << "progress updates expected, not just the final state";
    int last_measured = -1;
    for (const pb::JobUpdate& u : log->updates) {
      EXPECT_EQ(u.job().job_id(), job.job_id());
      EXPECT_GE(u.job().progress().measured(), last_measured) << "progress went backwards";
      last_measured = u.job().progress().measured();
    }
    EXPECT_EQ(log->updates.back().job().state(), pb::JOB_STATE_COMPLETED);
    EXPECT_EQ(log->updates.back().job().progress().measured(), 30);
  }
  EXPECT_FALSE(plain.updates.back().has_map()) << "include_map = false";
  ASSERT_TRUE(with_map.updates.back().has_map());
  EXPECT_GT(with_map.updates.back().map().mu_size(), 0);
  EXPECT_EQ(with_map.updates.back().map().samples_size(), 30)
      << "the last update's map must include the sample that completed the job";
  ITEST_ASSERT_OK_AND_ASSIGN(final_map, GetMap(stubs, job.job_id(), -1, false));
  EXPECT_EQ(final_map.map().samples_size(), 30) << "GetMap after completion";
  std::cout << "watch: " << plain.updates.size() << " updates (plain), " << with_map.updates.size()
            << " (with map) for 30 samples\n";
}

TEST(StandardServices, HealthIsServingAndReflectionListsTheApi) {
  ITEST_ASSERT_OK_AND_ASSIGN(server, ServerProcess::Start());
  auto health = grpc::health::v1::Health::NewStub(server->channel());
  grpc::health::v1::HealthCheckRequest check;
  grpc::health::v1::HealthCheckResponse serving;
  GRPC_ASSERT_OK(health->Check(Context().get(), check, &serving));
  EXPECT_EQ(serving.status(), grpc::health::v1::HealthCheckResponse::SERVING);

  auto reflection = grpc::reflection::v1alpha::ServerReflection::NewStub(server->channel());
  auto context = Context();
  auto stream = reflection->ServerReflectionInfo(context.get());
  grpc::reflection::v1alpha::ServerReflectionRequest list;
  list.set_list_services("*");
  ASSERT_TRUE(stream->Write(list));
  stream->WritesDone();
  grpc::reflection::v1alpha::ServerReflectionResponse listed;
  ASSERT_TRUE(stream->Read(&listed)) << "no reflection response";
  GRPC_EXPECT_OK(stream->Finish());
  std::set<std::string> services;
  for (const auto& s : listed.list_services_response().service()) services.insert(s.name());
  for (const char* name : {"surfmap.v1.ObjectService", "surfmap.v1.JobService", "surfmap.v1.ProbeService",
                           "surfmap.v1.MapService", "surfmap.v1.TraceService"}) {
    EXPECT_TRUE(services.count(name)) << "reflection does not list " << name;
  }
}

// Tools ask for reflection v1 first (v1alpha is the fallback): the server
// lists the API on v1 and answers a symbol with its file and the imports.
TEST(StandardServices, ReflectionV1ListsTheApiAndResolvesSymbols) {
  ITEST_ASSERT_OK_AND_ASSIGN(server, ServerProcess::Start());
  auto reflection = grpc::reflection::v1::ServerReflection::NewStub(server->channel());
  auto context = Context();
  auto stream = reflection->ServerReflectionInfo(context.get());
  grpc::reflection::v1::ServerReflectionRequest list;
  list.set_list_services("");
  ASSERT_TRUE(stream->Write(list));
  grpc::reflection::v1::ServerReflectionRequest symbol;
  symbol.set_file_containing_symbol("surfmap.v1.JobService");
  ASSERT_TRUE(stream->Write(symbol));
  grpc::reflection::v1::ServerReflectionRequest unknown;
  unknown.set_file_containing_symbol("surfmap.v1.NoSuchService");
  ASSERT_TRUE(stream->Write(unknown));
  stream->WritesDone();
  grpc::reflection::v1::ServerReflectionResponse listed, file, missing;
  ASSERT_TRUE(stream->Read(&listed)) << "no reflection v1 response";
  ASSERT_TRUE(stream->Read(&file));
  ASSERT_TRUE(stream->Read(&missing));
  GRPC_EXPECT_OK(stream->Finish());
  std::set<std::string> services;
  for (const auto& s : listed.list_services_response().service()) services.insert(s.name());
  for (const char* name : {"surfmap.v1.ObjectService", "surfmap.v1.JobService", "surfmap.v1.ProbeService",
                           "surfmap.v1.MapService", "surfmap.v1.TraceService", "grpc.reflection.v1.ServerReflection"}) {
    EXPECT_TRUE(services.count(name)) << "reflection v1 does not list " << name;
  }
  ASSERT_TRUE(file.has_file_descriptor_response()) << file.error_response().error_message();
  ASSERT_GE(file.file_descriptor_response().file_descriptor_proto_size(), 1);
  google::protobuf::FileDescriptorProto first;
  ASSERT_TRUE(first.ParseFromString(file.file_descriptor_response().file_descriptor_proto(0)));
  EXPECT_EQ(first.package(), "surfmap.v1");
  ASSERT_TRUE(missing.has_error_response());
  EXPECT_EQ(missing.error_response().error_code(), static_cast<int>(grpc::StatusCode::NOT_FOUND));
}

// Health per service name as well as the server as a whole ("").
TEST(StandardServices, HealthIsServingPerServiceName) {
  ITEST_ASSERT_OK_AND_ASSIGN(server, ServerProcess::Start());
  auto health = grpc::health::v1::Health::NewStub(server->channel());
  for (const char* name : {"", "surfmap.v1.ObjectService", "surfmap.v1.JobService", "surfmap.v1.ProbeService",
                           "surfmap.v1.MapService", "surfmap.v1.TraceService"}) {
    SCOPED_TRACE(std::string("service '") + name + "'");
    grpc::health::v1::HealthCheckRequest check;
    check.set_service(name);
    grpc::health::v1::HealthCheckResponse response;
    GRPC_ASSERT_OK(health->Check(Context().get(), check, &response));
    EXPECT_EQ(response.status(), grpc::health::v1::HealthCheckResponse::SERVING) << "service '" << name << "'";
  }
  grpc::health::v1::HealthCheckRequest unknown;
  unknown.set_service("surfmap.v1.NoSuchService");
  grpc::health::v1::HealthCheckResponse response;
  const grpc::Status status = health->Check(Context().get(), unknown, &response);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::NOT_FOUND);
}

TEST(Tokens, RolesAreEnforced) {
  const std::string read = "read-token-0123456789", probe = "probe-token-0123456789",
                    steer = "steer-token-0123456789";
  ServerOptions options;
  options.config_json = R"({"tokens": {")" + read + R"(": "read", ")" + probe + R"(": "probe", ")" + steer +
                        R"(": "steer"}})";
  ITEST_ASSERT_OK_AND_ASSIGN(server, ServerProcess::Start(options));
  ITEST_ASSERT_OK_AND_ASSIGN(rig, MakeSceneRig("bottle"));
  Stubs stubs(server->channel());

  auto list = [&](const std::string& token) {
    pb::ListObjectsResponse out;
    return stubs.objects->ListObjects(Context(60, token).get(), pb::ListObjectsRequest(), &out);
  };
  EXPECT_EQ(list("").error_code(), grpc::StatusCode::UNAUTHENTICATED) << Describe(list(""));
  EXPECT_EQ(list("not-a-token-0123456789").error_code(), grpc::StatusCode::UNAUTHENTICATED);
  GRPC_EXPECT_OK(list(read));
  GRPC_EXPECT_OK(list(probe));
  GRPC_EXPECT_OK(list(steer));

  auto denied = UploadSceneMesh(stubs, *rig, probe);
  EXPECT_EQ(denied.status().code(), absl::StatusCode::kPermissionDenied) << denied.status();
  ITEST_ASSERT_OK_AND_ASSIGN(object, UploadSceneMesh(stubs, *rig, steer));

  JobSpecOptions spec;
  spec.mode = pb::SAMPLING_MODE_UNIFORM;
  spec.finest_level = 0;
  const pb::JobSpec job_spec = MakeJobSpec(object.object_id(), spec);
  auto by_reader = CreateJob(stubs, job_spec, read);
  EXPECT_EQ(by_reader.status().code(), absl::StatusCode::kPermissionDenied) << by_reader.status();
  auto by_nobody = CreateJob(stubs, job_spec, "");
  EXPECT_EQ(by_nobody.status().code(), absl::StatusCode::kUnauthenticated) << by_nobody.status();
  ITEST_ASSERT_OK_AND_ASSIGN(job, CreateJob(stubs, job_spec, steer));

  auto lease = [&](const std::string& token) {
    pb::LeaseCommandRequest r;
    r.set_rig_id("rig-tok");
    r.set_job_id(job.job_id());
    pb::LeaseCommandResponse out;
    return stubs.probe->LeaseCommand(Context(60, token).get(), r, &out);
  };
  EXPECT_EQ(lease(read).error_code(), grpc::StatusCode::PERMISSION_DENIED) << Describe(lease(read));
  GRPC_EXPECT_OK(lease(probe));
  GRPC_EXPECT_OK(lease(steer));

  pb::SetJobStateRequest pause;
  pause.set_job_id(job.job_id());
  pb::SetJobStateResponse paused;
  EXPECT_EQ(stubs.jobs->PauseJob(Context(60, probe).get(), pause, &paused).error_code(),
            grpc::StatusCode::PERMISSION_DENIED);
  pb::GetJobRequest get;
  get.set_job_id(job.job_id());
  pb::GetJobResponse got;
  GRPC_EXPECT_OK(stubs.jobs->GetJob(Context(60, read).get(), get, &got));

  // The health check stays open: load balancers carry no tokens.
  auto health = grpc::health::v1::Health::NewStub(server->channel());
  grpc::health::v1::HealthCheckResponse serving;
  GRPC_EXPECT_OK(health->Check(Context().get(), grpc::health::v1::HealthCheckRequest(), &serving));
}

}  // namespace
}  // namespace surfmap::itest
