// Steering a job while rigs submit and dashboards watch: the service must
// answer every call within its deadline (no deadlock, no stall), and never
// acknowledge a trace it did not store.
#include <atomic>
#include <chrono>
#include <memory>
#include <set>
#include <thread>
#include <vector>

#include "absl/strings/str_cat.h"
#include "gtest/gtest.h"
#include "tests/support/job_helpers.h"
#include "tests/support/rig_fleet.h"
#include "tests/support/server_process.h"
#include "tests/support/status_matchers.h"

namespace surfmap::itest {
namespace {

using std::chrono::milliseconds;
using std::chrono::seconds;

// Each steering call gets this deadline: a lab operator's patience, and far
// above what a healthy server needs (an fsync).
constexpr double kSteeringDeadlineS = 5.0;
// The watchers' streams end when the job is cancelled; their deadline only
// guards against a hang, so it must outlast the whole test. The test's time is
// the map rebuilds the watchers and GetMap ask for (~0.5 s each on the plate's
// finest level, ~20 of them): 11 s here, 92 s under ThreadSanitizer alone and
// 135 s beside another test on two cores, which a 120 s deadline cut short.
// Under the ctest timeout (600 s), so a hang still fails as a hang.
constexpr double kWatchDeadlineS = 300.0;

grpc::Status Steer(Stubs& stubs, int64_t job_id, pb::JobState target, pb::SetJobStateResponse* response) {
  pb::SetJobStateRequest request;
  request.set_job_id(job_id);
  auto context = Context(kSteeringDeadlineS);
  switch (target) {
    case pb::JOB_STATE_PAUSED: return stubs.jobs->PauseJob(context.get(), request, response);
    case pb::JOB_STATE_RUNNING: return stubs.jobs->ResumeJob(context.get(), request, response);
    default: return stubs.jobs->CancelJob(context.get(), request, response);
  }
}

// A rig's error after the cancel is the job refusing a trace (FAILED_PRECONDITION,
// "cancelled"); anything else is a failure of the service.
void ExpectOnlyCancelRefusals(const RigFleetRecord& record) {
  for (const std::string& error : record.rpc_errors) {
    EXPECT_NE(error.find("FAILED_PRECONDITION"), std::string::npos) << error;
    EXPECT_NE(error.find("cancelled"), std::string::npos) << error;
  }
}

// Every acknowledged trace is stored with exactly the samples the rig sent,
// and the job holds no trace nobody was told about.
void ExpectAcksMatchStoredTraces(Stubs& stubs, int64_t job_id, const RigFleetRecord& record) {
  ITEST_ASSERT_OK_AND_ASSIGN(samples, ListSamples(stubs, job_id));
  std::set<int64_t> stored;
  for (const pb::Sample& s : samples.samples()) stored.insert(s.trace_id());
  std::set<int64_t> acked;
  for (const RigAck& ack : record.acks) {
    acked.insert(ack.trace_id);
    EXPECT_TRUE(stored.count(ack.trace_id)) << "acknowledged trace " << ack.trace_id << " is not stored";
    pb::GetTraceRequest request;
    request.set_trace_id(ack.trace_id);
    pb::GetTraceResponse trace;
    GRPC_ASSERT_OK(stubs.traces->GetTrace(Context().get(), request, &trace));
    std::string difference;
    EXPECT_TRUE(SameSamples(trace.samples(), ack.samples, &difference))
        << "trace " << ack.trace_id << " differs from what " << ack.rig << " sent: " << difference;
  }
  // A trace stored but never acknowledged can only be one whose reply was
  // lost in flight; the rigs here never lose a reply, so there is none.
  for (int64_t id : stored) EXPECT_TRUE(acked.count(id)) << "trace " << id << " stored but never acknowledged";
}

TEST(Steering, FortyPauseResumeRoundsWhileTwoRigsSubmitThenCancel) {
  ITEST_ASSERT_OK_AND_ASSIGN(scene, StartServerWithScene("plate"));
  JobSpecOptions spec;
  spec.mode = pb::SAMPLING_MODE_UNIFORM;
  spec.coarsest_level = 3;
  spec.finest_level = 3;
  ITEST_ASSERT_OK_AND_ASSIGN(job, CreateJob(*scene.stubs, MakeJobSpec(scene.object_id, spec)));

  RigFleetOptions options;
  options.rigs = 2;
  options.job_id = job.job_id();
  options.call_deadline_s = kSteeringDeadlineS;
  options.max_retry_sleep_s = 0.02;
  RigFleet fleet(scene.server->address(), *scene.rig, options);
  fleet.Start();
  // Let the rigs get going before the first pause.
  for (int i = 0; i < 500 && fleet.acked() < 4; ++i) std::this_thread::sleep_for(milliseconds(10));
  ASSERT_GE(fleet.acked(), 4) << "the rigs did not start submitting";

  for (int round = 0; round < 40; ++round) {
    pb::SetJobStateResponse response;
    grpc::Status paused = Steer(*scene.stubs, job.job_id(), pb::JOB_STATE_PAUSED, &response);
    ASSERT_TRUE(paused.ok()) << "round " << round << " pause: " << Describe(paused);
    EXPECT_EQ(response.job().state(), pb::JOB_STATE_PAUSED);
    std::this_thread::sleep_for(milliseconds(20));
    grpc::Status resumed = Steer(*scene.stubs, job.job_id(), pb::JOB_STATE_RUNNING, &response);
    ASSERT_TRUE(resumed.ok()) << "round " << round << " resume: " << Describe(resumed);
    EXPECT_EQ(response.job().state(), pb::JOB_STATE_RUNNING);
    std::this_thread::sleep_for(milliseconds(30));
  }
  const int acked_before_cancel = fleet.acked();
  pb::SetJobStateResponse response;
  GRPC_ASSERT_OK(Steer(*scene.stubs, job.job_id(), pb::JOB_STATE_CANCELLED, &response));
  EXPECT_EQ(response.job().state(), pb::JOB_STATE_CANCELLED);
  fleet.Join();  // rigs stop on job_finished (or a refused trace after the cancel)
  const RigFleetRecord record = fleet.record();
  ExpectOnlyCancelRefusals(record);
  EXPECT_GT(acked_before_cancel, 10) << "rigs should make progress between the pauses";
  ExpectAcksMatchStoredTraces(*scene.stubs, job.job_id(), record);
}

struct WatchResult {
  int updates = 0;
  int updates_with_map = 0;
  pb::JobState last_state = pb::JOB_STATE_UNSPECIFIED;
  grpc::Status status;
};

void WatchWithMap(const std::string& address, int64_t job_id, grpc::ClientContext* context, WatchResult* result) {
  Stubs stubs(ConnectedChannel(address, /*own_subchannel=*/true));
  pb::WatchJobRequest request;
  request.set_job_id(job_id);
  request.set_include_map(true);
  auto reader = stubs.jobs->WatchJob(context, request);
  pb::JobUpdate update;
  while (reader->Read(&update)) {
    ++result->updates;
    if (update.has_map() && update.map().mu_size() > 0) ++result->updates_with_map;
    result->last_state = update.job().state();
  }
  result->status = reader->Finish();
}

// Watcher threads that are joined however the test ends: a failed ASSERT
// returns early with the job still watched, so their streams are cancelled
// first (an unjoined std::thread would abort the whole test binary).
struct Watchers {
  std::vector<std::unique_ptr<grpc::ClientContext>> contexts;
  std::vector<std::thread> threads;
  void Join() {
    for (std::thread& t : threads) {
      if (t.joinable()) t.join();
    }
  }
  ~Watchers() {
    for (auto& context : contexts) context->TryCancel();
    Join();
  }
};

TEST(Steering, WatchersWithTheMapAndFourRigsWhileTheJobIsPausedResumedAndCancelled) {
  ITEST_ASSERT_OK_AND_ASSIGN(scene, StartServerWithScene("plate"));
  JobSpecOptions spec;
  spec.mode = pb::SAMPLING_MODE_UNIFORM;
  // Level 3's sites (as in the forty-round test): more drags than four rigs
  // finish in ten rounds, so every pause finds them submitting; level 2's
  // were done by round 8 once the served map cost more per read.
  spec.coarsest_level = 3;
  spec.finest_level = 3;
  ITEST_ASSERT_OK_AND_ASSIGN(job, CreateJob(*scene.stubs, MakeJobSpec(scene.object_id, spec)));

  std::vector<WatchResult> watches(3);
  Watchers watchers;
  for (WatchResult& w : watches) {
    grpc::ClientContext* context = watchers.contexts.emplace_back(Context(kWatchDeadlineS)).get();
    watchers.threads.emplace_back(
        [&, context, address = scene.server->address()] { WatchWithMap(address, job.job_id(), context, &w); });
  }
  RigFleetOptions options;
  options.rigs = 4;
  options.job_id = job.job_id();
  options.call_deadline_s = kSteeringDeadlineS;
  options.max_retry_sleep_s = 0.02;
  RigFleet fleet(scene.server->address(), *scene.rig, options);
  fleet.Start();
  for (int i = 0; i < 500 && fleet.acked() < 8; ++i) std::this_thread::sleep_for(milliseconds(10));
  ASSERT_GE(fleet.acked(), 8) << "the rigs did not start submitting";

  for (int round = 0; round < 10; ++round) {
    pb::SetJobStateResponse response;
    grpc::Status paused = Steer(*scene.stubs, job.job_id(), pb::JOB_STATE_PAUSED, &response);
    ASSERT_TRUE(paused.ok()) << "round " << round << " pause: " << Describe(paused);
    // Reads stay answered while paused and watched.
    ITEST_ASSERT_OK_AND_ASSIGN(info, GetJob(*scene.stubs, job.job_id()));
    EXPECT_EQ(info.state(), pb::JOB_STATE_PAUSED);
    ITEST_ASSERT_OK(GetMap(*scene.stubs, job.job_id(), -1, false).status());
    std::this_thread::sleep_for(milliseconds(30));
    grpc::Status resumed = Steer(*scene.stubs, job.job_id(), pb::JOB_STATE_RUNNING, &response);
    ASSERT_TRUE(resumed.ok()) << "round " << round << " resume: " << Describe(resumed);
    std::this_thread::sleep_for(milliseconds(50));
  }
  pb::SetJobStateResponse response;
  GRPC_ASSERT_OK(Steer(*scene.stubs, job.job_id(), pb::JOB_STATE_CANCELLED, &response));
  fleet.Join();
  watchers.Join();  // the streams end with the job
  const RigFleetRecord record = fleet.record();
  ExpectOnlyCancelRefusals(record);
  ExpectAcksMatchStoredTraces(*scene.stubs, job.job_id(), record);
  for (size_t i = 0; i < watches.size(); ++i) {
    GRPC_EXPECT_OK(watches[i].status);
    EXPECT_EQ(watches[i].last_state, pb::JOB_STATE_CANCELLED) << "watcher " << i << " missed the end of the job";
    EXPECT_GE(watches[i].updates_with_map, 2) << "watcher " << i;
  }
}

}  // namespace
}  // namespace surfmap::itest
