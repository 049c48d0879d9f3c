// RigLoop: a rig's work cycle against the server.
//
//   first:              resubmit every trace left in the spool by an earlier run
//   LeaseCommand(rig_id, job_id)
//     -> command:       driver.Execute, spool the trace, SubmitTrace, delete
//                       the spooled file on OK (or ReportFailure when the
//                       driver fails or the server cannot use the trace)
//     -> retry_after:   sleep that long (other rigs' results are awaited)
//     -> job_finished:  stop
//
// No measured trace is lost: it is in the spool (trace_spool.h) before the
// first submission and leaves it only on an OK answer (fresh or
// already_accepted), or for DIR/rejected/ with the reason when the server
// refuses it for good. UNAVAILABLE and DEADLINE_EXCEEDED (server down,
// restarting, busy) are retried with capped exponential backoff for
// `retry_for_s` per call; SubmitTrace is idempotent for the same rig and
// samples, so a retry of a submission that did get through answers
// `already_accepted`. When the retries run out the loop ends with the error
// and the trace stays in the spool for the next start.
//
// A stop request (the flag, set by a signal handler) is honoured between
// steps: the command being executed is finished and submitted, sleeps end at
// once, and no new command is leased.
#pragma once

#include <atomic>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>

#include <grpcpp/grpcpp.h>
#include "clients/sim/rig/rig_driver.h"
#include "clients/rig/probe_endpoint.h"
#include "clients/rig/trace_spool.h"

namespace surfmap::rig {

struct RigLoopOptions {
  std::string rig_id = "rig";
  std::int64_t job_id = 0;          // 0 = any running job
  int max_commands = 0;             // stop after this many executed commands; 0 = until the job finishes
  double retry_for_s = 300.0;       // per call: how long UNAVAILABLE / DEADLINE_EXCEEDED are retried
  double initial_backoff_s = 0.2;   // doubled per retry ...
  double max_backoff_s = 5.0;       // ... up to this
  double default_retry_after_s = 1.0;  // when the server sends no retry_after
  double max_retry_after_s = 10.0;     // cap on the server's retry_after
  // The frame of the driver's traces (SubmitTraceRequest.frame): unset = the
  // object's. A spooled trace keeps its frame and the command's registration
  // (spool_file.h) and is resubmitted with them, whatever this run's frame.
  surfmap::v1::TraceFrame frame = surfmap::v1::TRACE_FRAME_UNSPECIFIED;

  // False (and *why) for an empty, over-long or multi-line rig id, negative
  // counts, or non-positive / non-finite times.
  bool IsValid(std::string* why) const;
};

struct RigLoopSummary {
  int accepted = 0;         // traces of this run's commands the server accepted (incl. already_accepted)
  int already_accepted = 0;
  int resubmitted = 0;      // traces spooled by an earlier run, accepted now
  int rejected = 0;         // traces moved to the spool's rejected/ (refused for good, or unreadable)
  int failures = 0;         // commands reported as failed (driver error or unusable trace)
  int abandoned = 0;        // commands whose lease was lost, answered by another rig, or whose job ended
  int retries = 0;          // calls repeated after UNAVAILABLE / DEADLINE_EXCEEDED
  int spooled_left = -1;    // traces still in the spool at the end (-1: not counted)
  double elapsed_s = 0.0;
  bool job_finished = false;
  bool stopped = false;     // ended by the stop flag
  bool reached_max_commands = false;
  grpc::Status error;       // the error that ended the loop (OK otherwise)
  std::string error_rpc;    // the call (or "spool", "driver", "options") that failed

  int executed() const { return accepted + failures + abandoned; }
  double TracesPerSecond() const { return elapsed_s > 0 ? accepted / elapsed_s : 0.0; }
  // "rig A: 57 commands done, 1 failure, 0 abandoned, 2 retries in 12.3 s (4.6 traces/s); job finished"
  // plus "; 3 spooled traces resubmitted", "; 1 trace rejected", "; 2 traces left in the spool" when not 0.
  std::string Format(const std::string& rig_id) const;
};

// What the loop tells its user while it retries a call.
struct RetryNotice {
  std::string rpc;          // "SubmitTrace"
  grpc::Status status;      // the failure being retried
  int attempt = 0;          // 1 = the first call failed
  double wait_s = 0.0;      // until the next attempt
  double remaining_s = 0.0; // of retry_for_s: how much longer the call is retried
};

// "server unavailable, retrying for 4 min 50 s (SubmitTrace: UNAVAILABLE: <message>)";
// DEADLINE_EXCEEDED reads "server not answering".
std::string FormatRetryNotice(const RetryNotice& notice);

// "4 min 50 s", "50 s", "1.5 s", "2 h 5 min": rounded to whole seconds above 10 s.
std::string FormatWaitDuration(double seconds);

// Injected for tests; every member has a working default.
struct RigLoopHooks {
  std::function<void(double seconds)> sleep;            // default: sleeps in slices, waking on stop
  std::function<double()> now_s;                        // default: steady clock
  std::function<std::int64_t()> unix_ms;                // default: system clock (the spool's measured time)
  std::function<void(const surfmap::v1::JobProgress&)> on_progress;  // after each accepted trace
  std::function<void(const std::string&)> on_event;     // notable events (failures, refusals), one line each
  std::function<void(const RetryNotice&)> on_retry;     // before each retry wait (default: on_event)
};

// Which FailureKind a driver error reports: FAILED_PRECONDITION and
// OUT_OF_RANGE (the rig cannot reach or drag at the site) are UNREACHABLE,
// every other code TRANSIENT (see RigDriver).
surfmap::v1::FailureKind FailureKindOf(const absl::Status& driver_error);

class RigLoop {
 public:
  // `stop` may be null (never stops early). All references must outlive Run.
  RigLoop(ProbeEndpoint& endpoint, RigDriver& driver, TraceSpool& spool, RigLoopOptions options,
          const std::atomic<bool>* stop, RigLoopHooks hooks = {});

  // Resubmits the spool, then runs until the job finishes, max_commands are
  // executed, stop is set, or something fails for good (summary.error: a
  // non-retryable error such as NOT_FOUND job or PERMISSION_DENIED, retries
  // run out, the spool cannot be written, or the driver is broken).
  RigLoopSummary Run();

 private:
  enum class Step { kContinue, kEnd };
  // How a spooled trace's submission ended.
  enum class Delivery { kAccepted, kRefused, kUnusable, kKept };

  bool Stopping() const { return stop_ != nullptr && stop_->load(); }
  void Event(const std::string& line);
  // Calls `call` until it is OK, not retryable, retry_for_s has passed since
  // the first failure, or stop is set while waiting for a lease. Returns the
  // last status.
  grpc::Status WithRetries(const char* rpc, const std::function<grpc::Status()>& call);
  Step Fail(const char* rpc, const grpc::Status& status);
  Step ResubmitSpool();
  Step RunCommand(const surfmap::v1::ProbeCommand& command);
  // Submits the spooled `file` and settles it: deleted on OK, moved to
  // rejected/ on a definitive refusal, kept otherwise (summary.error set).
  Delivery Deliver(const std::filesystem::path& file, const SpooledTrace& spooled, bool lease_next);
  Step ReportFailure(std::int64_t command_id, const std::string& where, const std::string& reason,
                     surfmap::v1::FailureKind kind);

  ProbeEndpoint& endpoint_;
  RigDriver& driver_;
  TraceSpool& spool_;
  RigLoopOptions options_;
  const std::atomic<bool>* stop_;
  RigLoopHooks hooks_;
  RigLoopSummary summary_;
  // The lease a submission came back with (SubmitTrace lease_next): the next
  // command, without a LeaseCommand round trip.
  std::optional<surfmap::v1::LeaseCommandResponse> next_lease_;
  // The refusal behind the last Delivery::kUnusable (for the failure report).
  grpc::Status last_refusal_;
};

}  // namespace surfmap::rig
