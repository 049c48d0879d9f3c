#include "clients/rig_client/rig_loop.h"

#include <deque>
#include <optional>
#include <string>
#include <vector>

#include <gtest/gtest.h>

namespace surfmap::rig {
namespace {

namespace pb = ::surfmap::v1;

// A server scripted call by call: each queue holds the answers in order; an
// empty lease queue answers job_finished.
class ScriptedEndpoint : public ProbeEndpoint {
 public:
  struct LeaseAnswer {
    grpc::Status status;
    pb::LeaseCommandResponse response;
  };
  struct SubmitAnswer {
    grpc::Status status;
    bool already_accepted = false;
    std::optional<pb::LeaseCommandResponse> next;  // answered when the request asked lease_next
  };

  std::deque<LeaseAnswer> leases;
  std::deque<SubmitAnswer> submits;   // empty: accept
  std::deque<grpc::Status> failures;  // empty: accept
  std::vector<int64_t> submitted_ids;
  std::vector<size_t> submitted_sizes;
  std::vector<std::string> failure_reasons;
  std::vector<bool> asked_next;
  int lease_calls = 0;

  grpc::Status LeaseCommand(const pb::LeaseCommandRequest& request, pb::LeaseCommandResponse* response) override {
    ++lease_calls;
    EXPECT_EQ(request.rig_id(), "test-rig");
    if (leases.empty()) {
      response->set_job_finished(true);
      return grpc::Status::OK;
    }
    LeaseAnswer a = leases.front();
    leases.pop_front();
    *response = a.response;
    return a.status;
  }
  grpc::Status SubmitTrace(const pb::SubmitTraceRequest& request, pb::SubmitTraceResponse* response) override {
    submitted_ids.push_back(request.command_id());
    submitted_sizes.push_back(static_cast<size_t>(request.samples().t_size()));
    asked_next.push_back(request.lease_next());
    SubmitAnswer a;
    if (!submits.empty()) {
      a = submits.front();
      submits.pop_front();
    }
    if (a.status.ok()) {
      response->set_already_accepted(a.already_accepted);
      response->mutable_progress()->set_measured(static_cast<int>(submitted_ids.size()));
      if (request.lease_next() && a.next) *response->mutable_next() = *a.next;
    }
    return a.status;
  }
  grpc::Status ReportFailure(const pb::ReportFailureRequest& request, pb::ReportFailureResponse* response) override {
    failure_reasons.push_back(request.reason());
    grpc::Status s;
    if (!failures.empty()) {
      s = failures.front();
      failures.pop_front();
    }
    if (s.ok()) response->set_will_retry(true);
    return s;
  }
};

// Three-sample trace, or the configured error for listed command ids.
class FakeDriver : public RigDriver {
 public:
  std::vector<int64_t> executed;
  int64_t fail_command = -1;

  absl::StatusOr<DragTrace> Execute(const ProbeRequest& request) override {
    executed.push_back(request.command_id);
    if (request.command_id == fail_command) return absl::FailedPreconditionError("cannot reach the site");
    DragTrace trace;
    for (int i = 0; i < 3; ++i) {
      DragSample s;
      s.t = i;
      s.force = Eigen::Vector3d(0, 0, 5);
      s.phase = i == 0 ? DragPhase::kForward : i == 1 ? DragPhase::kPause : DragPhase::kReverse;
      trace.samples.push_back(s);
    }
    return trace;
  }
};

ScriptedEndpoint::LeaseAnswer Command(int64_t id) {
  ScriptedEndpoint::LeaseAnswer a;
  pb::ProbeCommand* c = a.response.mutable_command();
  c->set_command_id(id);
  c->set_job_id(1);
  c->mutable_normal()->set_z(1);
  c->mutable_drag_direction()->set_x(1);
  return a;
}

ScriptedEndpoint::LeaseAnswer RetryAfter(double seconds) {
  ScriptedEndpoint::LeaseAnswer a;
  a.response.mutable_retry_after()->set_seconds(static_cast<int64_t>(seconds));
  a.response.mutable_retry_after()->set_nanos(static_cast<int32_t>((seconds - static_cast<int64_t>(seconds)) * 1e9));
  return a;
}

ScriptedEndpoint::LeaseAnswer LeaseError(grpc::StatusCode code) {
  ScriptedEndpoint::LeaseAnswer a;
  a.status = grpc::Status(code, "scripted");
  return a;
}

struct Harness {
  ScriptedEndpoint endpoint;
  FakeDriver driver;
  RigLoopOptions options;
  std::vector<double> sleeps;
  std::vector<std::string> events;
  std::vector<int> progress;
  std::atomic<bool> stop{false};

  Harness() { options.rig_id = "test-rig"; }

  RigLoopSummary Run() {
    RigLoopHooks hooks;
    hooks.sleep = [this](double s) { sleeps.push_back(s); };
    double clock = 0;
    hooks.now_s = [clock]() mutable { return clock += 1.0; };
    hooks.on_event = [this](const std::string& e) { events.push_back(e); };
    hooks.on_progress = [this](const pb::JobProgress& p) { progress.push_back(p.measured()); };
    RigLoop loop(endpoint, driver, options, &stop, hooks);
    return loop.Run();
  }
};

TEST(RigLoopTest, ExecutesCommandsUntilTheJobFinishes) {
  Harness h;
  h.endpoint.leases = {Command(1), RetryAfter(0.5), Command(2)};
  RigLoopSummary s = h.Run();
  EXPECT_TRUE(s.error.ok()) << s.error.error_message();
  EXPECT_TRUE(s.job_finished);
  EXPECT_EQ(s.accepted, 2);
  EXPECT_EQ(s.failures, 0);
  EXPECT_EQ(h.driver.executed, (std::vector<int64_t>{1, 2}));
  EXPECT_EQ(h.endpoint.submitted_ids, (std::vector<int64_t>{1, 2}));
  EXPECT_EQ(h.endpoint.submitted_sizes, (std::vector<size_t>{3, 3}));
  EXPECT_EQ(h.sleeps, (std::vector<double>{0.5}));  // the server's retry_after
  EXPECT_EQ(h.progress, (std::vector<int>{1, 2}));
  EXPECT_EQ(h.endpoint.lease_calls, 4);
  EXPECT_DOUBLE_EQ(s.elapsed_s, 1.0);  // the fake clock ticks once per read
}

TEST(RigLoopTest, TheNextCommandComesWithTheAnswerWhenTheServerGivesIt) {
  Harness h;
  h.options.max_commands = 3;
  h.endpoint.leases = {Command(1)};
  ScriptedEndpoint::SubmitAnswer with_next;
  with_next.next = Command(2).response;
  ScriptedEndpoint::SubmitAnswer with_next_3;
  with_next_3.next = Command(3).response;
  h.endpoint.submits = {with_next, with_next_3, {}};
  RigLoopSummary s = h.Run();
  EXPECT_TRUE(s.error.ok()) << s.error.error_message();
  EXPECT_TRUE(s.reached_max_commands);
  EXPECT_EQ(h.driver.executed, (std::vector<int64_t>{1, 2, 3}));
  EXPECT_EQ(h.endpoint.lease_calls, 1) << "commands 2 and 3 came with the answers";
  // The last command of the rig's budget asks for nothing: a lease nobody
  // executes would hold its site until it expires.
  EXPECT_EQ(h.endpoint.asked_next, (std::vector<bool>{true, true, false}));
}

TEST(RigLoopTest, MissingOrHugeRetryAfterUsesDefaultAndCap) {
  Harness h;
  h.options.default_retry_after_s = 0.25;
  h.options.max_retry_after_s = 3;
  h.endpoint.leases = {ScriptedEndpoint::LeaseAnswer{}, RetryAfter(60)};
  RigLoopSummary s = h.Run();
  EXPECT_TRUE(s.job_finished);
  EXPECT_EQ(h.sleeps, (std::vector<double>{0.25, 3.0}));
}

TEST(RigLoopTest, RetriesSubmitWithBackoffAndCountsAlreadyAccepted) {
  Harness h;
  h.options.initial_backoff_s = 0.1;
  h.options.max_backoff_s = 0.3;
  h.endpoint.leases = {Command(5)};
  h.endpoint.submits = {{grpc::Status(grpc::StatusCode::UNAVAILABLE, "down")},
                        {grpc::Status(grpc::StatusCode::DEADLINE_EXCEEDED, "slow")},
                        {grpc::Status(grpc::StatusCode::UNAVAILABLE, "down")},
                        {grpc::Status::OK, /*already_accepted=*/true}};
  RigLoopSummary s = h.Run();
  EXPECT_TRUE(s.error.ok());
  EXPECT_EQ(s.accepted, 1);
  EXPECT_EQ(s.already_accepted, 1);
  EXPECT_EQ(s.retries, 3);
  EXPECT_EQ(h.endpoint.submitted_ids, (std::vector<int64_t>{5, 5, 5, 5}));  // same command id every time
  EXPECT_EQ(h.sleeps, (std::vector<double>{0.1, 0.2, 0.3}));
  EXPECT_EQ(h.driver.executed.size(), 1u);  // not re-executed
  EXPECT_EQ(h.events.size(), 3u);
  EXPECT_NE(h.events[0].find("test-rig: SubmitTrace: UNAVAILABLE: down (attempt 1 of 8)"), std::string::npos)
      << h.events[0];
}

TEST(RigLoopTest, GivesUpWhenRetriesRunOut) {
  Harness h;
  h.options.max_attempts = 3;
  h.endpoint.leases = {LeaseError(grpc::StatusCode::UNAVAILABLE), LeaseError(grpc::StatusCode::UNAVAILABLE),
                       LeaseError(grpc::StatusCode::UNAVAILABLE), Command(1)};
  RigLoopSummary s = h.Run();
  EXPECT_EQ(s.error.error_code(), grpc::StatusCode::UNAVAILABLE);
  EXPECT_EQ(s.error_rpc, "LeaseCommand");
  EXPECT_EQ(s.accepted, 0);
  EXPECT_EQ(h.endpoint.lease_calls, 3);
}

TEST(RigLoopTest, DriverFailureIsReported) {
  Harness h;
  h.driver.fail_command = 2;
  h.endpoint.leases = {Command(1), Command(2), Command(3)};
  RigLoopSummary s = h.Run();
  EXPECT_TRUE(s.error.ok());
  EXPECT_EQ(s.accepted, 2);
  EXPECT_EQ(s.failures, 1);
  ASSERT_EQ(h.endpoint.failure_reasons.size(), 1u);
  EXPECT_EQ(h.endpoint.failure_reasons[0], "rig: FAILED_PRECONDITION: cannot reach the site");
  EXPECT_EQ(h.endpoint.submitted_ids, (std::vector<int64_t>{1, 3}));
}

TEST(RigLoopTest, RejectedTraceBecomesAFailureReport) {
  Harness h;
  h.endpoint.leases = {Command(4)};
  h.endpoint.submits = {{grpc::Status(grpc::StatusCode::INVALID_ARGUMENT, "trace: too few samples")}};
  RigLoopSummary s = h.Run();
  EXPECT_TRUE(s.error.ok());
  EXPECT_EQ(s.failures, 1);
  ASSERT_EQ(h.endpoint.failure_reasons.size(), 1u);
  EXPECT_EQ(h.endpoint.failure_reasons[0], "trace rejected: INVALID_ARGUMENT: trace: too few samples");
}

TEST(RigLoopTest, LostLeaseIsAbandonedAndTheLoopGoesOn) {
  Harness h;
  h.endpoint.leases = {Command(1), Command(2)};
  h.endpoint.submits = {{grpc::Status(grpc::StatusCode::FAILED_PRECONDITION, "command 1 is not leased to test-rig")}};
  RigLoopSummary s = h.Run();
  EXPECT_TRUE(s.error.ok());
  EXPECT_EQ(s.abandoned, 1);
  EXPECT_EQ(s.accepted, 1);
  EXPECT_TRUE(s.job_finished);
}

TEST(RigLoopTest, PermissionDeniedEndsTheLoop) {
  Harness h;
  h.endpoint.leases = {LeaseError(grpc::StatusCode::PERMISSION_DENIED), Command(1)};
  RigLoopSummary s = h.Run();
  EXPECT_EQ(s.error.error_code(), grpc::StatusCode::PERMISSION_DENIED);
  EXPECT_EQ(h.endpoint.lease_calls, 1);
  EXPECT_FALSE(s.job_finished);
}

TEST(RigLoopTest, MaxCommandsStopsTheLoop) {
  Harness h;
  h.options.max_commands = 2;
  h.endpoint.leases = {Command(1), Command(2), Command(3)};
  RigLoopSummary s = h.Run();
  EXPECT_TRUE(s.reached_max_commands);
  EXPECT_FALSE(s.job_finished);
  EXPECT_EQ(s.accepted, 2);
  EXPECT_EQ(h.endpoint.lease_calls, 2);
}

TEST(RigLoopTest, StopFinishesTheCurrentCommandThenLeaves) {
  Harness h;
  h.endpoint.leases = {Command(1), Command(2)};
  // The "signal" arrives while the first trace is being submitted.
  h.endpoint.submits = {{grpc::Status(grpc::StatusCode::UNAVAILABLE, "blip")}};
  // Set stop from inside the first backoff sleep.
  RigLoopHooks hooks;
  std::vector<double> sleeps;
  hooks.sleep = [&](double s) {
    sleeps.push_back(s);
    h.stop = true;
  };
  RigLoop loop(h.endpoint, h.driver, h.options, &h.stop, hooks);
  RigLoopSummary s = loop.Run();
  EXPECT_TRUE(s.stopped);
  EXPECT_EQ(s.accepted, 1);  // the measured trace was still delivered
  EXPECT_EQ(h.endpoint.submitted_ids, (std::vector<int64_t>{1, 1}));
  EXPECT_EQ(h.endpoint.lease_calls, 1);
  EXPECT_NE(s.Format("test-rig").find("stopped by signal"), std::string::npos);
}

TEST(RigLoopTest, InvalidOptionsAreReported) {
  Harness h;
  h.options.rig_id = "";
  RigLoopSummary s = h.Run();
  EXPECT_EQ(s.error.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_EQ(h.endpoint.lease_calls, 0);
}

TEST(RigLoopSummaryTest, FormatsOneLine) {
  RigLoopSummary s;
  s.accepted = 57;
  s.failures = 1;
  s.retries = 2;
  s.elapsed_s = 12.0;
  s.job_finished = true;
  EXPECT_EQ(s.Format("rig-a"),
            "rig-a: 57 commands done, 1 failure, 0 abandoned, 2 retries in 12.0 s (4.75 traces/s); job finished");
}

}  // namespace
}  // namespace surfmap::rig
