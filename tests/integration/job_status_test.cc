// What a job reports about itself while it runs, through the real server:
// WatchJob's latest_sample, JobInfo.updated moving with every change (and
// surviving a restart), progress.leased against progress.issued, and the
// RefitJob default for an unset EstimatorSettings.noise_aware.
#include <atomic>
#include <chrono>
#include <map>
#include <optional>
#include <thread>

#include "absl/strings/str_cat.h"
#include "gtest/gtest.h"
#include "tests/support/job_helpers.h"
#include "tests/support/rig_fleet.h"
#include "tests/support/server_process.h"
#include "tests/support/status_matchers.h"

namespace surfmap::itest {
namespace {

using std::chrono::milliseconds;

int64_t UnixMsNow() {
  return std::chrono::duration_cast<milliseconds>(std::chrono::system_clock::now().time_since_epoch()).count();
}

int64_t ToUnixMs(const google::protobuf::Timestamp& t) { return t.seconds() * 1000 + t.nanos() / 1'000'000; }


// A uniform job over the bottle's coarsest vertices.

absl::StatusOr<pb::SubmitTraceResponse> Submit(Stubs& stubs, const SimulatedRig& rig, const pb::ProbeCommand& command,
                                               const std::string& rig_id) {
  pb::SubmitTraceResponse response;
  absl::StatusOr<pb::SubmitTraceRequest> request = ExecuteOnRig(rig, command, rig_id);
  if (!request.ok()) return request.status();
  grpc::Status status = stubs.probe->SubmitTrace(Context().get(), *request, &response);
  if (!status.ok()) return FromGrpc(status, "SubmitTrace");
  return response;
}

absl::StatusOr<pb::JobInfo> ListedJob(Stubs& stubs, int64_t job_id) {
  pb::ListJobsRequest request;
  pb::ListJobsResponse response;
  grpc::Status status = stubs.jobs->ListJobs(Context().get(), request, &response);
  if (!status.ok()) return FromGrpc(status, "ListJobs");
  for (const pb::JobInfo& job : response.jobs()) {
    if (job.job_id() == job_id) return job;
  }
  return absl::NotFoundError(absl::StrCat("ListJobs does not list job ", job_id));
}

// The first update of a new watch (the job's state on subscription).
absl::StatusOr<pb::JobUpdate> FirstUpdate(Stubs& stubs, int64_t job_id) {
  pb::WatchJobRequest request;
  request.set_job_id(job_id);
  auto context = Context(30);
  auto reader = stubs.jobs->WatchJob(context.get(), request);
  pb::JobUpdate update;
  if (!reader->Read(&update)) return FromGrpc(reader->Finish(), "WatchJob");
  context->TryCancel();
  (void)reader->Finish();
  return update;
}

TEST(JobStatus, WatchUpdatesCarryTheNewestAcceptedSample) {
  ITEST_ASSERT_OK_AND_ASSIGN(setup, StartServerWithScene("bottle"));
  Stubs& stubs = *setup.stubs;
  constexpr int kBudget = 8;
  ITEST_ASSERT_OK_AND_ASSIGN(job, CreateJob(stubs, UniformLevel0Spec(setup.object_id, kBudget)));

  std::vector<pb::JobUpdate> updates;
  grpc::Status watch_status;
  std::atomic<bool> started{false};
  std::thread watcher([&] {
    pb::WatchJobRequest request;
    request.set_job_id(job.job_id());
    auto context = Context(120);
    auto reader = stubs.jobs->WatchJob(context.get(), request);
    pb::JobUpdate update;
    while (reader->Read(&update)) {
      updates.push_back(update);
      started = true;
    }
    watch_status = reader->Finish();
  });
  for (int i = 0; i < 500 && !started; ++i) std::this_thread::sleep_for(milliseconds(10));
  ASSERT_TRUE(started) << "no first update within 5 s of subscribing";

  // One rig, so traces are accepted one after another.
  RigFleetOptions fleet_options;
  fleet_options.rigs = 1;
  fleet_options.job_id = job.job_id();
  RigFleetRecord record = RigFleet(setup.server->address(), *setup.rig, fleet_options).Run();
  for (const std::string& error : record.rpc_errors) ADD_FAILURE() << error;
  watcher.join();  // ends by itself when the job completes
  GRPC_EXPECT_OK(watch_status);

  ITEST_ASSERT_OK_AND_ASSIGN(samples, ListSamples(stubs, job.job_id()));
  ASSERT_EQ(samples.samples_size(), kBudget);
  std::map<int64_t, pb::Sample> stored;
  int64_t newest = 0;
  for (const pb::Sample& s : samples.samples()) {
    stored[s.trace_id()] = s;
    newest = std::max(newest, s.trace_id());
  }

  ASSERT_GE(updates.size(), 2u);
  EXPECT_FALSE(updates.front().has_latest_sample()) << "no trace yet when the watch started";
  int with_sample = 0;
  int64_t last_trace = 0;
  for (const pb::JobUpdate& u : updates) {
    if (u.job().progress().measured() == 0) {
      EXPECT_FALSE(u.has_latest_sample()) << "a sample before any trace: " << u.ShortDebugString();
      continue;
    }
    ASSERT_TRUE(u.has_latest_sample()) << "an update after an accepted trace must carry the newest sample; measured "
                                       << u.job().progress().measured();
    const pb::Sample& latest = u.latest_sample();
    ++with_sample;
    EXPECT_GT(latest.trace_id(), 0);
    EXPECT_GE(latest.trace_id(), last_trace) << "latest_sample went backwards";
    last_trace = latest.trace_id();
    auto it = stored.find(latest.trace_id());
    ASSERT_NE(it, stored.end()) << "latest_sample names trace " << latest.trace_id() << ", which is not stored";
    const pb::Sample& truth = it->second;
    EXPECT_EQ(latest.job_id(), job.job_id());
    EXPECT_EQ(latest.command_id(), truth.command_id());
    EXPECT_EQ(latest.site().level(), truth.site().level());
    EXPECT_EQ(latest.site().vertex(), truth.site().vertex());
    EXPECT_NEAR(latest.position().x(), truth.position().x(), 1e-12);
    EXPECT_NEAR(latest.position().y(), truth.position().y(), 1e-12);
    EXPECT_NEAR(latest.position().z(), truth.position().z(), 1e-12);
    EXPECT_EQ(latest.fit().version(), 1);
    EXPECT_EQ(latest.fit().fit_id(), truth.fit().fit_id()) << "no refit ran: the latest fit is the first";
    EXPECT_DOUBLE_EQ(latest.fit().friction().mu(), truth.fit().friction().mu());
    EXPECT_GT(latest.fit().friction().pair_count(), 0);
    EXPECT_EQ(ToUnixMs(latest.received()), ToUnixMs(truth.received()));
  }
  EXPECT_GE(with_sample, 1);
  ASSERT_EQ(updates.back().job().state(), pb::JOB_STATE_COMPLETED);
  ASSERT_TRUE(updates.back().has_latest_sample()) << "the final update carries the trace that completed the job";
  EXPECT_EQ(updates.back().latest_sample().trace_id(), newest);
  std::cout << updates.size() << " updates, " << with_sample << " with a latest_sample, for " << kBudget
            << " traces\n";
}

TEST(JobStatus, UpdatedMovesWithEveryTraceAndFailureAndSurvivesARestart) {
  ITEST_ASSERT_OK_AND_ASSIGN(setup, StartServerWithScene("bottle"));
  ITEST_ASSERT_OK_AND_ASSIGN(job, CreateJob(*setup.stubs, UniformLevel0Spec(setup.object_id, 0)));
  const int64_t created = ToUnixMs(job.created());
  EXPECT_EQ(ToUnixMs(job.updated()), created);

  // The clocks of this process and the server are the same clock; waiting
  // makes every later change land on a later millisecond.
  std::this_thread::sleep_for(milliseconds(20));
  ITEST_ASSERT_OK_AND_ASSIGN(first, LeaseOne(*setup.stubs, job.job_id(), "rig-a"));
  const int64_t before_trace = UnixMsNow();
  ITEST_ASSERT_OK_AND_ASSIGN(accepted, Submit(*setup.stubs, *setup.rig, first, "rig-a"));
  const int64_t after_trace = UnixMsNow();
  ITEST_ASSERT_OK_AND_ASSIGN(after_one, GetJob(*setup.stubs, job.job_id()));
  const int64_t trace_updated = ToUnixMs(after_one.updated());
  EXPECT_GE(trace_updated, before_trace) << "GetJob.updated must move with an accepted trace";
  EXPECT_LE(trace_updated, after_trace);
  EXPECT_EQ(trace_updated, ToUnixMs(accepted.sample().received())) << "the change is the trace's acceptance";
  EXPECT_EQ(ToUnixMs(after_one.created()), created) << "created never changes";
  ITEST_ASSERT_OK_AND_ASSIGN(listed, ListedJob(*setup.stubs, job.job_id()));
  EXPECT_EQ(ToUnixMs(listed.updated()), trace_updated) << "ListJobs shows the same time as GetJob";

  std::this_thread::sleep_for(milliseconds(20));
  ITEST_ASSERT_OK_AND_ASSIGN(second, LeaseOne(*setup.stubs, job.job_id(), "rig-a"));
  const int64_t before_failure = UnixMsNow();
  pb::ReportFailureRequest failure;
  failure.set_command_id(second.command_id());
  failure.set_rig_id("rig-a");
  failure.set_reason("probe slipped off the edge");
  pb::ReportFailureResponse failure_response;
  GRPC_ASSERT_OK(setup.stubs->probe->ReportFailure(Context().get(), failure, &failure_response));
  ITEST_ASSERT_OK_AND_ASSIGN(after_failure, GetJob(*setup.stubs, job.job_id()));
  const int64_t failure_updated = ToUnixMs(after_failure.updated());
  EXPECT_GE(failure_updated, before_failure) << "GetJob.updated must move with a reported failure";
  EXPECT_GT(failure_updated, trace_updated);

  // A restarted server (here after a crash) rebuilds the job: the time of its
  // last change and its newest sample come back from the database.
  ITEST_ASSERT_OK(setup.server->Kill());
  ITEST_ASSERT_OK(setup.server->Restart());
  Stubs stubs(setup.server->channel());
  ITEST_ASSERT_OK_AND_ASSIGN(restored, GetJob(stubs, job.job_id()));
  const int64_t restored_updated = ToUnixMs(restored.updated());
  EXPECT_GT(restored_updated, trace_updated) << "the failure after the trace is the last change";
  EXPECT_LE(restored_updated, failure_updated) << "never later than the change itself";
  ITEST_ASSERT_OK_AND_ASSIGN(update, FirstUpdate(stubs, job.job_id()));
  ASSERT_TRUE(update.has_latest_sample()) << "the newest sample is restored with the job";
  EXPECT_EQ(update.latest_sample().trace_id(), accepted.sample().trace_id());
  EXPECT_EQ(update.latest_sample().command_id(), first.command_id());
  EXPECT_EQ(ToUnixMs(update.latest_sample().received()), trace_updated);
}

TEST(JobStatus, LeasedCountsCommandsAtARigWhileIssuedCountsTheQueueToo) {
  ITEST_ASSERT_OK_AND_ASSIGN(setup, StartServerWithScene("bottle"));
  Stubs& stubs = *setup.stubs;
  ITEST_ASSERT_OK_AND_ASSIGN(job, CreateJob(stubs, UniformLevel0Spec(setup.object_id, 0)));
  ASSERT_TRUE(job.progress().has_leased());
  EXPECT_EQ(job.progress().leased(), 0);
  const int sites = job.progress().issued();
  ASSERT_GE(sites, 4) << "the plan queues every coarsest vertex at once";
  EXPECT_EQ(job.progress().pending(), 0);

  ITEST_ASSERT_OK_AND_ASSIGN(a, LeaseOne(stubs, job.job_id(), "rig-a"));
  ITEST_ASSERT_OK_AND_ASSIGN(b, LeaseOne(stubs, job.job_id(), "rig-b"));
  ITEST_ASSERT_OK_AND_ASSIGN(c, LeaseOne(stubs, job.job_id(), "rig-c"));
  ITEST_ASSERT_OK_AND_ASSIGN(three, GetJob(stubs, job.job_id()));
  EXPECT_EQ(three.progress().issued(), sites) << "leasing does not change what the plan issued";
  ASSERT_TRUE(three.progress().has_leased());
  EXPECT_EQ(three.progress().leased(), 3);
  ITEST_ASSERT_OK_AND_ASSIGN(listed, ListedJob(stubs, job.job_id()));
  EXPECT_EQ(listed.progress().leased(), 3);
  ITEST_ASSERT_OK_AND_ASSIGN(plan, GetPlan(stubs, job.job_id()));
  ASSERT_TRUE(plan.progress().has_leased());
  EXPECT_EQ(plan.progress().leased(), 3);
  ITEST_ASSERT_OK_AND_ASSIGN(update, FirstUpdate(stubs, job.job_id()));
  EXPECT_EQ(update.job().progress().leased(), 3) << "WatchJob";
  // Per level too (this job has level 0 only), wherever the total is given.
  for (const pb::JobProgress* progress : {&three.progress(), &listed.progress(), &plan.progress(),
                                          &update.job().progress()}) {
    ASSERT_EQ(progress->levels_size(), 1);
    ASSERT_TRUE(progress->levels(0).has_leased());
    EXPECT_EQ(progress->levels(0).leased(), 3);
  }

  ITEST_ASSERT_OK_AND_ASSIGN(accepted, Submit(stubs, *setup.rig, a, "rig-a"));
  EXPECT_FALSE(accepted.progress().has_leased()) << "not counted on the trace path";
  EXPECT_FALSE(accepted.progress().levels(0).has_leased());
  EXPECT_EQ(accepted.progress().measured(), 1);
  ITEST_ASSERT_OK_AND_ASSIGN(after_trace, GetJob(stubs, job.job_id()));
  EXPECT_EQ(after_trace.progress().measured(), 1);
  EXPECT_EQ(after_trace.progress().issued(), sites - 1);
  EXPECT_EQ(after_trace.progress().leased(), 2);

  pb::ReportFailureRequest failure;
  failure.set_command_id(b.command_id());
  failure.set_rig_id("rig-b");
  failure.set_reason("no contact");
  pb::ReportFailureResponse failure_response;
  GRPC_ASSERT_OK(stubs.probe->ReportFailure(Context().get(), failure, &failure_response));
  ASSERT_TRUE(failure_response.will_retry());
  ITEST_ASSERT_OK_AND_ASSIGN(after_failure, GetJob(stubs, job.job_id()));
  EXPECT_EQ(after_failure.progress().issued(), sites - 1) << "the retry is queued again";
  EXPECT_EQ(after_failure.progress().leased(), 1) << "only rig-c holds a command";
  EXPECT_EQ(after_failure.progress().levels(0).leased(), 1);

  pb::SetJobStateRequest pause;
  pause.set_job_id(job.job_id());
  pb::SetJobStateResponse paused;
  GRPC_ASSERT_OK(stubs.jobs->PauseJob(Context().get(), pause, &paused));
  EXPECT_EQ(paused.job().progress().leased(), 1) << "a paused job's held leases still count";
  (void)c;
}

TEST(JobStatus, AnExpiredLeaseIsNoLongerCountedAsLeased) {
  ITEST_ASSERT_OK_AND_ASSIGN(setup, StartServerWithScene("bottle"));
  Stubs& stubs = *setup.stubs;
  ITEST_ASSERT_OK_AND_ASSIGN(job, CreateJob(stubs, UniformLevel0Spec(setup.object_id, 0, /*lease_s=*/0.3)));
  ITEST_ASSERT_OK_AND_ASSIGN(command, LeaseOne(stubs, job.job_id(), "rig-slow"));
  ITEST_ASSERT_OK_AND_ASSIGN(held, GetJob(stubs, job.job_id()));
  const int64_t deadline = ToUnixMs(command.lease_deadline());
  // Only meaningful while the lease still runs (a stalled machine may pass it).
  if (UnixMsNow() + 50 < deadline) {
    EXPECT_EQ(held.progress().leased(), 1);
  }
  while (UnixMsNow() <= deadline + 50) std::this_thread::sleep_for(milliseconds(20));
  ITEST_ASSERT_OK_AND_ASSIGN(expired, GetJob(stubs, job.job_id()));
  EXPECT_EQ(expired.progress().leased(), 0) << "the lease expired; any rig may lease the command again";
  EXPECT_EQ(expired.progress().issued(), held.progress().issued()) << "still issued: it waits for a rig";
}

std::string FitOptionsOf(Stubs& stubs, int64_t trace_id, int32_t version) {
  pb::GetSampleRequest request;
  request.set_trace_id(trace_id);
  request.set_fit_version(version);
  pb::GetSampleResponse response;
  grpc::Status status = stubs.maps->GetSample(Context().get(), request, &response);
  EXPECT_TRUE(status.ok()) << Describe(status);
  EXPECT_EQ(response.sample().fit().version(), version);
  return response.sample().fit().options_json();
}

TEST(JobStatus, RefitWithoutNoiseAwareUsesTheEstimatorDefault) {
  ITEST_ASSERT_OK_AND_ASSIGN(setup, StartServerWithScene("bottle"));
  Stubs& stubs = *setup.stubs;
  ITEST_ASSERT_OK_AND_ASSIGN(job, CreateJob(stubs, UniformLevel0Spec(setup.object_id, 2)));
  RigFleetOptions fleet_options;
  fleet_options.rigs = 1;
  fleet_options.job_id = job.job_id();
  RigFleetRecord record = RigFleet(setup.server->address(), *setup.rig, fleet_options).Run();
  for (const std::string& error : record.rpc_errors) ADD_FAILURE() << error;
  ASSERT_FALSE(record.acks.empty());
  const int64_t trace_id = record.acks.front().trace_id;

  auto refit = [&](std::optional<bool> noise_aware) -> pb::RefitJobResponse {
    pb::RefitJobRequest request;
    request.set_job_id(job.job_id());
    request.mutable_settings()->set_ar_method(pb::AR_METHOD_BURG);
    if (noise_aware.has_value()) request.mutable_settings()->set_noise_aware(*noise_aware);
    pb::RefitJobResponse response;
    grpc::Status status = stubs.traces->RefitJob(Context().get(), request, &response);
    EXPECT_TRUE(status.ok()) << Describe(status);
    return response;
  };
  const pb::RefitJobResponse unset = refit(std::nullopt);
  EXPECT_EQ(unset.fit_version(), 2);
  EXPECT_NE(FitOptionsOf(stubs, trace_id, 2).find("\"noise_aware\":true"), std::string::npos)
      << "unset noise_aware must mean the estimator's default (true): " << FitOptionsOf(stubs, trace_id, 2);
  const pb::RefitJobResponse off = refit(false);
  EXPECT_EQ(off.fit_version(), 3);
  EXPECT_NE(FitOptionsOf(stubs, trace_id, 3).find("\"noise_aware\":false"), std::string::npos)
      << FitOptionsOf(stubs, trace_id, 3);
  const pb::RefitJobResponse on = refit(true);
  EXPECT_EQ(on.fit_version(), 4);
  EXPECT_NE(FitOptionsOf(stubs, trace_id, 4).find("\"noise_aware\":true"), std::string::npos);
  EXPECT_NE(FitOptionsOf(stubs, trace_id, 1).find("\"noise_aware\":true"), std::string::npos)
      << "the fit on arrival uses the default too";
}

}  // namespace
}  // namespace surfmap::itest
