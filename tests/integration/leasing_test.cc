// Leases and idempotent submission through the real server: a retried
// submission stores nothing twice, concurrent rigs never share a lease, and
// an expired lease goes to another rig under the same command id.
#include <atomic>
#include <map>
#include <mutex>
#include <set>
#include <thread>

#include <google/protobuf/util/message_differencer.h>

#include "gtest/gtest.h"
#include "tests/support/db_snapshot.h"
#include "tests/support/job_helpers.h"
#include "tests/support/server_process.h"
#include "tests/support/status_matchers.h"

namespace surfmap::itest {
namespace {

using std::chrono::milliseconds;



TEST(Leasing, ResubmittingTheSameTraceIsAcknowledgedOnceAndStoredOnce) {
  ITEST_ASSERT_OK_AND_ASSIGN(setup, StartServerWithScene("bottle"));
  Stubs& stubs = *setup.stubs;
  ITEST_ASSERT_OK_AND_ASSIGN(job, CreateJob(stubs, UniformLevel0Spec(setup.object_id)));
  ITEST_ASSERT_OK_AND_ASSIGN(command, LeaseOne(stubs, job.job_id(), "rig-a"));
  ITEST_ASSERT_OK_AND_ASSIGN(request, ExecuteOnRig(*setup.rig, command, "rig-a"));

  ITEST_ASSERT_OK_AND_ASSIGN(before, TakeDbSnapshot(setup.server->db_path()));
  pb::SubmitTraceResponse first, second, third;
  GRPC_ASSERT_OK(stubs.probe->SubmitTrace(Context().get(), request, &first));
  ITEST_ASSERT_OK_AND_ASSIGN(after_first, TakeDbSnapshot(setup.server->db_path()));
  GRPC_ASSERT_OK(stubs.probe->SubmitTrace(Context().get(), request, &second));
  GRPC_ASSERT_OK(stubs.probe->SubmitTrace(Context().get(), request, &third));
  ITEST_ASSERT_OK_AND_ASSIGN(after_retries, TakeDbSnapshot(setup.server->db_path()));

  EXPECT_FALSE(first.already_accepted());
  EXPECT_TRUE(second.already_accepted());
  // The reply to a new trace is built from the fit in memory, a retry's from
  // the stored rows: both must be exactly what GetSample reads back.
  {
    pb::GetSampleRequest get_sample;
    get_sample.set_trace_id(first.sample().trace_id());
    pb::GetSampleResponse stored;
    GRPC_ASSERT_OK(stubs.maps->GetSample(Context().get(), get_sample, &stored));
    EXPECT_TRUE(google::protobuf::util::MessageDifferencer::Equals(first.sample(), stored.sample()))
        << "reply " << first.sample().ShortDebugString() << "\nstored " << stored.sample().ShortDebugString();
    EXPECT_TRUE(google::protobuf::util::MessageDifferencer::Equals(second.sample(), stored.sample()))
        << "retry " << second.sample().ShortDebugString();
  }
  EXPECT_TRUE(third.already_accepted());
  EXPECT_EQ(second.sample().trace_id(), first.sample().trace_id());
  EXPECT_EQ(third.sample().trace_id(), first.sample().trace_id());
  EXPECT_EQ(second.sample().fit().friction().mu(), first.sample().fit().friction().mu());
  EXPECT_EQ(after_first.row_counts["traces"], before.row_counts["traces"] + 1);
  EXPECT_EQ(after_first.row_counts["fits"], before.row_counts["fits"] + 1);
  EXPECT_EQ(after_retries.row_counts["traces"], after_first.row_counts["traces"]) << "a retry stored a trace";
  EXPECT_EQ(after_retries.row_counts["fits"], after_first.row_counts["fits"]) << "a retry stored a fit";
  ITEST_ASSERT_OK_AND_ASSIGN(samples, ListSamples(stubs, job.job_id()));
  EXPECT_EQ(samples.samples_size(), 1);
  ITEST_ASSERT_OK_AND_ASSIGN(plan, GetPlan(stubs, job.job_id()));
  EXPECT_EQ(plan.progress().measured(), 1);

  // The same command id with DIFFERENT samples is not a retry: it must not
  // replace the stored trace. The rule (probe_protocol.h, Store::AcceptTraceAsync):
  // other samples for an answered command get ALREADY_EXISTS naming the stored trace.
  pb::SubmitTraceRequest altered = request;
  altered.mutable_samples()->set_fz(3, altered.samples().fz(3) + 0.25);
  pb::SubmitTraceResponse altered_response;
  grpc::Status status = stubs.probe->SubmitTrace(Context().get(), altered, &altered_response);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::ALREADY_EXISTS) << Describe(status);
  pb::GetTraceRequest get;
  get.set_trace_id(first.sample().trace_id());
  pb::GetTraceResponse stored;
  GRPC_ASSERT_OK(stubs.traces->GetTrace(Context().get(), get, &stored));
  std::string difference;
  EXPECT_TRUE(SameSamples(stored.samples(), request.samples(), &difference)) << difference;
}

TEST(Leasing, ConcurrentRigsNeverHoldTheSameCommand) {
  ITEST_ASSERT_OK_AND_ASSIGN(setup, StartServerWithScene("bottle"));
  Stubs& stubs = *setup.stubs;
  JobSpecOptions spec;
  spec.mode = pb::SAMPLING_MODE_UNIFORM;
  spec.coarsest_level = 1;
  spec.finest_level = 1;  // 322 sites
  ITEST_ASSERT_OK_AND_ASSIGN(job, CreateJob(stubs, MakeJobSpec(setup.object_id, spec)));

  constexpr int kThreads = 16;
  std::mutex mutex;
  std::map<int64_t, std::vector<std::string>> holders;
  std::vector<std::string> errors;
  std::vector<std::thread> threads;
  for (int i = 0; i < kThreads; ++i) {
    threads.emplace_back([&, i] {
      const std::string rig_id = "rig-" + std::to_string(i);
      Stubs own(setup.server->NewChannel());
      int empty_in_a_row = 0;
      while (empty_in_a_row < 3) {
        pb::LeaseCommandRequest request;
        request.set_rig_id(rig_id);
        request.set_job_id(job.job_id());
        pb::LeaseCommandResponse response;
        grpc::Status status = own.probe->LeaseCommand(Context().get(), request, &response);
        std::lock_guard<std::mutex> lock(mutex);
        if (!status.ok()) {
          errors.push_back(rig_id + ": " + Describe(status));
          return;
        }
        if (response.job_finished()) {
          errors.push_back(rig_id + ": job_finished while commands were only leased");
          return;
        }
        if (!response.has_command() || response.command().command_id() == 0) {
          ++empty_in_a_row;
          continue;
        }
        empty_in_a_row = 0;
        holders[response.command().command_id()].push_back(rig_id);
      }
    });
  }
  for (std::thread& t : threads) t.join();
  for (const std::string& e : errors) ADD_FAILURE() << e;
  int leased = 0;
  for (const auto& [command, rigs] : holders) {
    leased += static_cast<int>(rigs.size());
    EXPECT_EQ(rigs.size(), 1u) << "command " << command << " leased to " << rigs.size() << " rigs at once";
  }
  EXPECT_GT(leased, kThreads) << "too few commands to test concurrency";
  ITEST_ASSERT_OK_AND_ASSIGN(plan, GetPlan(stubs, job.job_id()));
  EXPECT_EQ(plan.progress().issued(), static_cast<int>(holders.size()))
      << "sites issued by the plan vs distinct commands the rigs hold";
  std::cout << kThreads << " rigs leased " << leased << " commands; plan: " << plan.progress().ShortDebugString()
            << "\n";
}

TEST(Leasing, AnExpiredLeaseIsReissuedToAnotherRigWithTheSameCommandId) {
  ITEST_ASSERT_OK_AND_ASSIGN(setup, StartServerWithScene("bottle"));
  Stubs& stubs = *setup.stubs;
  ITEST_ASSERT_OK_AND_ASSIGN(job, CreateJob(stubs, UniformLevel0Spec(setup.object_id, 0, /*lease_s=*/0.3)));
  ITEST_ASSERT_OK_AND_ASSIGN(abandoned, LeaseOne(stubs, job.job_id(), "rig-slow"));
  const auto lease_length = std::chrono::seconds(abandoned.lease_deadline().seconds()) +
                            std::chrono::nanoseconds(abandoned.lease_deadline().nanos());
  const auto now = std::chrono::system_clock::now().time_since_epoch();
  EXPECT_LT(lease_length - now, milliseconds(1500)) << "the job asked for a 0.3 s lease";
  std::this_thread::sleep_for(milliseconds(700));

  // The other rig leases until the abandoned command comes back (it may get
  // other pending commands first).
  pb::ProbeCommand reissued;
  for (int i = 0; i < 400 && reissued.command_id() == 0; ++i) {
    ITEST_ASSERT_OK_AND_ASSIGN(command, LeaseOne(stubs, job.job_id(), "rig-fast"));
    if (command.command_id() == abandoned.command_id()) reissued = command;
  }
  ASSERT_EQ(reissued.command_id(), abandoned.command_id()) << "the expired lease was never re-issued";
  EXPECT_EQ(reissued.site().vertex(), abandoned.site().vertex());
  EXPECT_EQ(reissued.site().level(), abandoned.site().level());

  pb::SubmitTraceResponse fresh;
  ITEST_ASSERT_OK_AND_ASSIGN(fresh_request, ExecuteOnRig(*setup.rig, reissued, "rig-fast"));
  GRPC_ASSERT_OK(stubs.probe->SubmitTrace(Context().get(), fresh_request, &fresh));
  EXPECT_FALSE(fresh.already_accepted());

  // The slow rig finally submits the same command. Its samples are not
  // stored, so it must not hear OK (not even already_accepted, which would
  // say its measurement was kept): ALREADY_EXISTS names the rig that measured.
  ITEST_ASSERT_OK_AND_ASSIGN(late_request, ExecuteOnRig(*setup.rig, abandoned, "rig-slow"));
  pb::SubmitTraceResponse late;
  grpc::Status status = stubs.probe->SubmitTrace(Context().get(), late_request, &late);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::ALREADY_EXISTS) << Describe(status);
  EXPECT_NE(status.error_message().find("rig-fast"), std::string::npos) << Describe(status);
  ITEST_ASSERT_OK_AND_ASSIGN(samples, ListSamples(stubs, job.job_id()));
  int for_command = 0;
  for (const pb::Sample& s : samples.samples()) for_command += s.command_id() == abandoned.command_id();
  EXPECT_EQ(for_command, 1);
}

}  // namespace
}  // namespace surfmap::itest

namespace surfmap::itest {
namespace {

// SubmitTrace with lease_next: the answer carries the rig's next command,
// leased to it in the same durable write; nobody else gets that command; the
// last answer of a job says the job is finished.
TEST(Leasing, ASubmissionCanLeaseTheRigsNextCommand) {
  ITEST_ASSERT_OK_AND_ASSIGN(setup, StartServerWithScene("bottle"));
  Stubs& stubs = *setup.stubs;
  ITEST_ASSERT_OK_AND_ASSIGN(job, CreateJob(stubs, UniformLevel0Spec(setup.object_id, /*budget=*/4)));
  ITEST_ASSERT_OK_AND_ASSIGN(command, LeaseOne(stubs, job.job_id(), "rig-a"));

  std::set<int64_t> executed;
  int leased_by_answers = 0;
  bool finished = false;
  for (int i = 0; i < 10 && !finished; ++i) {
    ASSERT_TRUE(executed.insert(command.command_id()).second) << "command " << command.command_id() << " twice";
    ITEST_ASSERT_OK_AND_ASSIGN(request, ExecuteOnRig(*setup.rig, command, "rig-a"));
    request.set_lease_next(true);
    pb::SubmitTraceResponse response;
    GRPC_ASSERT_OK(stubs.probe->SubmitTrace(Context().get(), request, &response));
    ASSERT_TRUE(response.has_next());
    if (response.next().job_finished()) {
      finished = true;
      break;
    }
    ASSERT_TRUE(response.next().has_command()) << response.next().ShortDebugString();
    command = response.next().command();
    ++leased_by_answers;
    EXPECT_GT(command.lease_deadline().seconds(), 0);
    // Leased to rig-a: another rig cannot have it, or submit for it.
    ITEST_ASSERT_OK_AND_ASSIGN(stolen, ExecuteOnRig(*setup.rig, command, "rig-b"));
    pb::SubmitTraceResponse stolen_response;
    grpc::Status status = stubs.probe->SubmitTrace(Context().get(), stolen, &stolen_response);
    EXPECT_EQ(status.error_code(), grpc::StatusCode::FAILED_PRECONDITION) << Describe(status);
    ITEST_ASSERT_OK_AND_ASSIGN(info, GetJob(stubs, job.job_id()));
    EXPECT_EQ(info.progress().leased(), 1) << "exactly the command the answer handed out";
  }
  EXPECT_TRUE(finished) << "the last answer says the job is finished";
  EXPECT_EQ(executed.size(), 4u);
  EXPECT_EQ(leased_by_answers, 3);
  ITEST_ASSERT_OK_AND_ASSIGN(done, GetJob(stubs, job.job_id()));
  EXPECT_EQ(done.state(), pb::JOB_STATE_COMPLETED);
  EXPECT_EQ(done.progress().measured(), 4);
}

}  // namespace
}  // namespace surfmap::itest
