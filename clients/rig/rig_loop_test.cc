#include "clients/rig/rig_loop.h"

#include <algorithm>
#include <cmath>
#include <deque>
#include <fstream>
#include <sstream>
#include <optional>
#include <utility>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include "absl/strings/str_cat.h"
#include "clients/rig/test_dir_for_test.h"

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
    // A constructor, not an aggregate: the scripts name only what they need
    // ({status} or {status, already_accepted}) without missing-initializer
    // warnings on every line.
    SubmitAnswer() = default;
    SubmitAnswer(grpc::Status s, bool accepted = false, std::optional<pb::LeaseCommandResponse> n = std::nullopt)
        : status(std::move(s)), already_accepted(accepted), next(std::move(n)) {}
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
  std::vector<pb::FailureKind> failure_kinds;
  std::vector<std::string> submitted_rigs;
  std::vector<bool> asked_next;
  int lease_calls = 0;
  std::function<void(const pb::SubmitTraceRequest&)> on_submit;  // sees each submission as it arrives

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
    if (on_submit) on_submit(request);
    submitted_ids.push_back(request.command_id());
    submitted_rigs.push_back(request.rig_id());
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
    failure_kinds.push_back(request.kind());
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
  absl::Status failure = absl::FailedPreconditionError("cannot reach the site");

  absl::StatusOr<DragTrace> Execute(const ProbeRequest& request) override {
    executed.push_back(request.command_id);
    if (request.command_id == fail_command) return failure;
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
  c->set_attempt(1);
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

// A fresh spool per test; the fake clock advances only by the loop's sleeps.
struct Harness {
  TestDir dir;
  std::unique_ptr<TraceSpool> spool;
  ScriptedEndpoint endpoint;
  FakeDriver driver;
  RigLoopOptions options;
  std::vector<double> sleeps;
  std::vector<std::string> events;
  std::vector<RetryNotice> retries;
  std::vector<int> progress;
  std::atomic<bool> stop{false};
  double clock = 0;

  Harness() {
    options.rig_id = "test-rig";
    spool = *TraceSpool::Open(dir.path() / "spool");
  }

  RigLoopHooks Hooks() {
    RigLoopHooks hooks;
    hooks.sleep = [this](double s) {
      sleeps.push_back(s);
      clock += s;
    };
    hooks.now_s = [this] { return clock; };
    hooks.unix_ms = [] { return std::int64_t{1'000}; };
    hooks.on_event = [this](const std::string& e) { events.push_back(e); };
    hooks.on_retry = [this](const RetryNotice& n) { retries.push_back(n); };
    hooks.on_progress = [this](const pb::JobProgress& p) { progress.push_back(p.measured()); };
    return hooks;
  }

  RigLoopSummary Run() {
    RigLoop loop(endpoint, driver, *spool, options, &stop, Hooks());
    return loop.Run();
  }

  std::vector<std::filesystem::path> Pending() { return *spool->Pending(); }
  std::vector<std::string> Rejected() {
    std::vector<std::string> names;
    for (const auto& entry : std::filesystem::directory_iterator(spool->rejected_dir())) {
      names.push_back(entry.path().filename().string());
    }
    std::sort(names.begin(), names.end());
    return names;
  }
};

std::string ReadText(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::ostringstream out;
  out << in.rdbuf();
  return out.str();
}

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
  EXPECT_DOUBLE_EQ(s.elapsed_s, 0.5);  // the fake clock moves with the sleeps
  EXPECT_EQ(s.spooled_left, 0);
  EXPECT_TRUE(h.Pending().empty()) << "accepted traces leave the spool";
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
  ASSERT_EQ(h.retries.size(), 3u);
  EXPECT_EQ(h.retries[0].rpc, "SubmitTrace");
  EXPECT_EQ(h.retries[0].attempt, 1);
  EXPECT_DOUBLE_EQ(h.retries[0].remaining_s, 300.0);
  EXPECT_DOUBLE_EQ(h.retries[2].remaining_s, 300.0 - 0.3);  // measured from the first failure
  EXPECT_EQ(FormatRetryNotice(h.retries[1]),
            "server not answering, retrying for 5 min (SubmitTrace: DEADLINE_EXCEEDED: slow)");
  EXPECT_TRUE(h.Pending().empty());
}

TEST(RigLoopTest, EveryTraceIsSpooledBeforeItIsSubmitted) {
  Harness h;
  h.endpoint.leases = {Command(11), Command(12)};
  std::vector<std::string> spooled_at_submit;
  h.endpoint.on_submit = [&](const pb::SubmitTraceRequest& request) {
    const std::vector<std::filesystem::path> pending = h.Pending();
    for (const auto& file : pending) {
      SpooledTrace spooled = *h.spool->Read(file);
      spooled_at_submit.push_back(absl::StrCat(spooled.header.command_id, "/", spooled.header.job_id, "/",
                                               spooled.header.attempt, "/", spooled.header.rig_id, "/",
                                               spooled.trace.samples.size(), " for ", request.command_id()));
    }
  };
  RigLoopSummary s = h.Run();
  EXPECT_TRUE(s.error.ok());
  EXPECT_EQ(spooled_at_submit, (std::vector<std::string>{"11/1/1/test-rig/3 for 11", "12/1/1/test-rig/3 for 12"}));
  EXPECT_TRUE(h.Pending().empty());
  EXPECT_TRUE(h.Rejected().empty());
}

TEST(RigLoopTest, GivesUpWhenRetryForHasPassed) {
  Harness h;
  h.options.retry_for_s = 1.0;
  h.endpoint.leases = {LeaseError(grpc::StatusCode::UNAVAILABLE), LeaseError(grpc::StatusCode::UNAVAILABLE),
                       LeaseError(grpc::StatusCode::UNAVAILABLE), LeaseError(grpc::StatusCode::UNAVAILABLE),
                       Command(1)};
  RigLoopSummary s = h.Run();
  EXPECT_EQ(s.error.error_code(), grpc::StatusCode::UNAVAILABLE);
  EXPECT_EQ(s.error_rpc, "LeaseCommand");
  EXPECT_EQ(s.accepted, 0);
  // Failures at t = 0, 0.2, 0.6 and 1.0: the last wait is cut to what is left.
  ASSERT_EQ(h.sleeps.size(), 3u);
  EXPECT_DOUBLE_EQ(h.sleeps[0], 0.2);
  EXPECT_DOUBLE_EQ(h.sleeps[1], 0.4);
  EXPECT_NEAR(h.sleeps[2], 0.4, 1e-12);
  EXPECT_EQ(h.endpoint.lease_calls, 4);
  ASSERT_FALSE(h.events.empty());
  EXPECT_EQ(h.events.back(), "test-rig: LeaseCommand: UNAVAILABLE: scripted; gave up after retrying for 1.0 s");
}

TEST(RigLoopTest, ATraceWhoseRetriesRunOutStaysInTheSpoolForTheNextStart) {
  Harness h;
  h.options.retry_for_s = 2.0;
  h.endpoint.leases = {Command(7)};
  for (int i = 0; i < 20; ++i) h.endpoint.submits.push_back({grpc::Status(grpc::StatusCode::UNAVAILABLE, "down")});
  RigLoopSummary s = h.Run();
  EXPECT_EQ(s.error.error_code(), grpc::StatusCode::UNAVAILABLE);
  EXPECT_EQ(s.error_rpc, "SubmitTrace");
  EXPECT_EQ(s.spooled_left, 1);
  ASSERT_EQ(h.Pending().size(), 1u);
  EXPECT_EQ(h.spool->Read(h.Pending()[0])->header.command_id, 7);
  EXPECT_NE(s.Format("test-rig").find("1 trace left in the spool; ended by an error"), std::string::npos)
      << s.Format("test-rig");

  // The next run delivers it first, then leases.
  Harness& next = h;
  next.endpoint.submits.clear();
  next.endpoint.submitted_ids.clear();
  next.endpoint.asked_next.clear();
  next.endpoint.leases = {Command(8)};
  RigLoopSummary again = next.Run();
  EXPECT_TRUE(again.error.ok()) << again.error.error_message();
  EXPECT_EQ(again.resubmitted, 1);
  EXPECT_EQ(again.accepted, 1) << "command 8";
  EXPECT_EQ(next.endpoint.submitted_ids, (std::vector<int64_t>{7, 8}));
  EXPECT_EQ(next.endpoint.asked_next, (std::vector<bool>{false, true}))
      << "a resubmission leases nothing: it may be of another job";
  EXPECT_TRUE(next.Pending().empty());
  EXPECT_NE(again.Format("test-rig").find("; 1 spooled trace resubmitted; job finished"), std::string::npos);
}

TEST(RigLoopTest, ResubmitsWithTheRigIdThatHeldTheLease) {
  Harness h;
  SpoolHeader header;
  header.command_id = 3;
  header.job_id = 9;
  header.rig_id = "old-name";
  header.measured_unix_ms = 5;
  FakeDriver maker;
  maker.executed.clear();
  ASSERT_TRUE(h.spool->Add(header, *maker.Execute(ProbeRequest{})).ok());
  h.endpoint.submits = {{grpc::Status::OK, /*already_accepted=*/true}};
  RigLoopSummary s = h.Run();
  EXPECT_TRUE(s.error.ok());
  EXPECT_EQ(h.endpoint.submitted_rigs, (std::vector<std::string>{"old-name"}));
  EXPECT_EQ(s.resubmitted, 1);
  EXPECT_EQ(s.already_accepted, 1);
  EXPECT_EQ(s.accepted, 0) << "not a command of this run";
  ASSERT_FALSE(h.events.empty());
  EXPECT_EQ(h.events[0].rfind("test-rig: resubmitting 1 spooled trace from ", 0), 0u) << h.events[0];
}

TEST(RigLoopTest, ASpooledTraceIsResubmittedInItsOwnFrameWithItsRegistration) {
  Harness h;
  SpoolHeader header;
  header.command_id = 3;
  header.job_id = 9;
  header.rig_id = "test-rig";
  header.measured_unix_ms = 5;
  header.frame = TraceFrame::kRigBase;
  header.registration_id = 6;
  FakeDriver maker;
  ASSERT_TRUE(h.spool->Add(header, *maker.Execute(ProbeRequest{})).ok());
  header.command_id = 4;
  header.measured_unix_ms = 6;
  header.frame = TraceFrame::kObject;
  header.registration_id = 0;
  ASSERT_TRUE(h.spool->Add(header, *maker.Execute(ProbeRequest{})).ok());
  std::vector<std::string> sent;
  h.endpoint.on_submit = [&](const pb::SubmitTraceRequest& r) {
    sent.push_back(absl::StrCat(r.command_id(), " ", pb::TraceFrame_Name(r.frame()), " ", r.registration_id()));
  };
  h.options.frame = pb::TRACE_FRAME_RIG_BASE_SENSOR_FORCES;  // this run's frame is neither
  RigLoopSummary s = h.Run();
  EXPECT_TRUE(s.error.ok()) << s.error.error_message();
  EXPECT_EQ(s.resubmitted, 2);
  EXPECT_EQ(sent, (std::vector<std::string>{"3 TRACE_FRAME_RIG_BASE 6", "4 TRACE_FRAME_OBJECT 0"}));
}

TEST(RigLoopTest, AnUnreadableSpoolFileIsMovedToRejected) {
  Harness h;
  { std::ofstream(h.spool->dir() / "0000000000001-command-4.trace.csv") << "t,x\n1,2\n"; }
  RigLoopSummary s = h.Run();
  EXPECT_TRUE(s.error.ok());
  EXPECT_EQ(s.rejected, 1);
  EXPECT_TRUE(h.endpoint.submitted_ids.empty());
  EXPECT_EQ(h.Rejected(), (std::vector<std::string>{"0000000000001-command-4.trace.csv",
                                                    "0000000000001-command-4.trace.csv.reason"}));
  const std::string reason = ReadText(h.spool->rejected_dir() / "0000000000001-command-4.trace.csv.reason");
  EXPECT_EQ(reason.rfind("unreadable: ", 0), 0u) << reason;
  EXPECT_NE(reason.find("not a spool file"), std::string::npos) << reason;
}

TEST(RigLoopTest, DefinitiveRefusalsMoveTheTraceToRejectedWithTheReason) {
  struct Case {
    grpc::StatusCode code;
    bool reported;  // the site is given back with ReportFailure
  };
  for (const Case c : {Case{grpc::StatusCode::ALREADY_EXISTS, false}, Case{grpc::StatusCode::FAILED_PRECONDITION, false},
                       Case{grpc::StatusCode::NOT_FOUND, false}, Case{grpc::StatusCode::INVALID_ARGUMENT, true},
                       Case{grpc::StatusCode::RESOURCE_EXHAUSTED, true}}) {
    Harness h;
    h.endpoint.leases = {Command(21)};
    h.endpoint.submits = {{grpc::Status(c.code, "the server's reason")}};
    RigLoopSummary s = h.Run();
    const std::string code(cli::StatusCodeName(c.code));
    EXPECT_TRUE(s.error.ok()) << code;
    EXPECT_EQ(s.rejected, 1) << code;
    EXPECT_EQ(s.abandoned, c.reported ? 0 : 1) << code;
    EXPECT_EQ(s.failures, c.reported ? 1 : 0) << code;
    EXPECT_EQ(h.endpoint.failure_reasons.size(), c.reported ? 1u : 0u) << code;
    EXPECT_TRUE(h.Pending().empty()) << code;
    ASSERT_EQ(h.Rejected(), (std::vector<std::string>{"0000000001000-command-21.trace.csv",
                                                      "0000000001000-command-21.trace.csv.reason"}))
        << code;
    const std::string reason = ReadText(h.spool->rejected_dir() / "0000000001000-command-21.trace.csv.reason");
    EXPECT_EQ(reason.rfind("SubmitTrace: " + code + ": the server's reason\n", 0), 0u) << reason;
  }
}

TEST(RigLoopTest, OtherErrorsKeepTheTraceAndEndTheLoop) {
  Harness h;
  h.endpoint.leases = {Command(30), Command(31)};
  h.endpoint.submits = {{grpc::Status(grpc::StatusCode::PERMISSION_DENIED, "token has role read")}};
  RigLoopSummary s = h.Run();
  EXPECT_EQ(s.error.error_code(), grpc::StatusCode::PERMISSION_DENIED);
  EXPECT_EQ(s.error_rpc, "SubmitTrace");
  EXPECT_EQ(h.Pending().size(), 1u) << "kept for a run with the right token";
  EXPECT_TRUE(h.Rejected().empty());
  EXPECT_EQ(h.driver.executed, (std::vector<int64_t>{30}));
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
  EXPECT_EQ(h.endpoint.failure_reasons[0], "rig: cannot reach the site");
  EXPECT_EQ(h.endpoint.failure_kinds, (std::vector<pb::FailureKind>{pb::FAILURE_KIND_UNREACHABLE}));
  EXPECT_EQ(h.endpoint.submitted_ids, (std::vector<int64_t>{1, 3}));
  EXPECT_TRUE(h.Pending().empty() && h.Rejected().empty()) << "nothing measured, nothing spooled";
}

TEST(RigLoopTest, DriverErrorsChooseTheFailureKind) {
  EXPECT_EQ(FailureKindOf(absl::FailedPreconditionError("outside the workspace")), pb::FAILURE_KIND_UNREACHABLE);
  EXPECT_EQ(FailureKindOf(absl::OutOfRangeError("beyond the arm's reach")), pb::FAILURE_KIND_UNREACHABLE);
  EXPECT_EQ(FailureKindOf(absl::UnavailableError("force limit tripped")), pb::FAILURE_KIND_TRANSIENT);
  EXPECT_EQ(FailureKindOf(absl::DeadlineExceededError("driver timed out")), pb::FAILURE_KIND_TRANSIENT);
}

TEST(RigLoopTest, ABrokenOrStoppedDriverEndsTheLoopAfterReporting) {
  for (const absl::Status& status : {absl::InternalError("driver wrote 'hello' on stdout"),
                                     absl::AbortedError("emergency stop pressed")}) {
    Harness h;
    h.driver.fail_command = 1;
    h.driver.failure = status;
    h.endpoint.leases = {Command(1), Command(2)};
    RigLoopSummary s = h.Run();
    EXPECT_EQ(s.error.error_code(), static_cast<grpc::StatusCode>(static_cast<int>(status.code())));
    EXPECT_EQ(s.error_rpc, "driver");
    EXPECT_EQ(h.endpoint.failure_kinds, (std::vector<pb::FailureKind>{pb::FAILURE_KIND_TRANSIENT}))
        << "the site is given back first";
    EXPECT_EQ(h.driver.executed, (std::vector<int64_t>{1}));
  }
}

TEST(RigLoopTest, AnInvalidTraceIsKeptInRejectedAndReported) {
  Harness h;
  h.driver.fail_command = -1;
  struct NanDriver : RigDriver {
    absl::StatusOr<DragTrace> Execute(const ProbeRequest& request) override {
      FakeDriver inner;
      DragTrace trace = *inner.Execute(request);
      trace.samples[1].force.z() = std::nan("");
      return trace;
    }
  } nan_driver;
  h.endpoint.leases = {Command(40)};
  RigLoop loop(h.endpoint, nan_driver, *h.spool, h.options, &h.stop, h.Hooks());
  RigLoopSummary s = loop.Run();
  EXPECT_TRUE(s.error.ok());
  EXPECT_EQ(s.rejected, 1);
  EXPECT_EQ(s.failures, 1);
  EXPECT_TRUE(h.endpoint.submitted_ids.empty()) << "the server would refuse it too";
  ASSERT_EQ(h.endpoint.failure_reasons.size(), 1u);
  EXPECT_EQ(h.endpoint.failure_reasons[0].rfind("rig: invalid trace: trace is invalid (", 0), 0u)
      << h.endpoint.failure_reasons[0];
  EXPECT_EQ(h.Rejected().size(), 2u);
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
  RigLoop loop(h.endpoint, h.driver, *h.spool, h.options, &h.stop, hooks);
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

TEST(RigLoopTest, WaitDurationsReadAsAPersonWouldSayThem) {
  EXPECT_EQ(FormatWaitDuration(0), "0 s");
  EXPECT_EQ(FormatWaitDuration(1.25), "1.2 s");
  EXPECT_EQ(FormatWaitDuration(9.96), "10.0 s");
  EXPECT_EQ(FormatWaitDuration(50.4), "50 s");
  EXPECT_EQ(FormatWaitDuration(290), "4 min 50 s");
  EXPECT_EQ(FormatWaitDuration(300), "5 min");
  EXPECT_EQ(FormatWaitDuration(7500), "2 h 5 min");
  EXPECT_EQ(FormatWaitDuration(7200), "2 h");
  RetryNotice notice{"SubmitTrace", grpc::Status(grpc::StatusCode::UNAVAILABLE, "Connection refused"), 3, 0.8, 290};
  EXPECT_EQ(FormatRetryNotice(notice),
            "server unavailable, retrying for 4 min 50 s (SubmitTrace: UNAVAILABLE: Connection refused)");
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
