// RigLoop: a rig's work cycle against the server.
//
//   LeaseCommand(rig_id, job_id)
//     -> command:       driver.Execute, then SubmitTrace (or ReportFailure
//                       when the driver fails or the server rejects the trace)
//     -> retry_after:   sleep that long (other rigs' results are awaited)
//     -> job_finished:  stop
//
// SubmitTrace is idempotent on command_id, so a submission that met
// UNAVAILABLE or DEADLINE_EXCEEDED is retried with exponential backoff (the
// server answers `already_accepted` if the first attempt got through); the
// same holds for every call here. A lost lease (FAILED_PRECONDITION on
// submit) abandons the command: the server has re-issued it to another rig.
//
// A stop request (the flag, set by a signal handler) is honoured between
// steps: the command being executed is finished and submitted, sleeps end at
// once, and no new command is leased.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>

#include <grpcpp/grpcpp.h>
#include "clients/rig/rig_driver.h"
#include "clients/rig_client/probe_endpoint.h"

namespace surfmap::rig {

struct RigLoopOptions {
  std::string rig_id = "rig";
  std::int64_t job_id = 0;          // 0 = any running job
  int max_commands = 0;             // stop after this many executed commands; 0 = until the job finishes
  int max_attempts = 8;             // per call, on UNAVAILABLE / DEADLINE_EXCEEDED
  double initial_backoff_s = 0.2;   // doubled per retry ...
  double max_backoff_s = 5.0;       // ... up to this
  double default_retry_after_s = 1.0;  // when the server sends no retry_after
  double max_retry_after_s = 10.0;     // cap on the server's retry_after

  // False (and *why) for an empty or over-long rig id, negative counts, or
  // non-positive / non-finite times.
  bool IsValid(std::string* why) const;
};

struct RigLoopSummary {
  int accepted = 0;         // traces the server accepted (including already_accepted retries)
  int already_accepted = 0;
  int failures = 0;         // commands reported as failed (driver error or rejected trace)
  int abandoned = 0;        // commands whose lease was lost or whose job ended meanwhile
  int retries = 0;          // calls repeated after UNAVAILABLE / DEADLINE_EXCEEDED
  double elapsed_s = 0.0;
  bool job_finished = false;
  bool stopped = false;     // ended by the stop flag
  bool reached_max_commands = false;
  grpc::Status error;       // the error that ended the loop (OK otherwise)
  std::string error_rpc;    // the call that failed

  int executed() const { return accepted + failures + abandoned; }
  double TracesPerSecond() const { return elapsed_s > 0 ? accepted / elapsed_s : 0.0; }
  // "rig A: 57 commands done, 1 failure, 0 abandoned, 2 retries in 12.3 s (4.6 traces/s); job finished"
  std::string Format(const std::string& rig_id) const;
};

// Injected for tests; every member has a working default.
struct RigLoopHooks {
  std::function<void(double seconds)> sleep;            // default: sleeps in slices, waking on stop
  std::function<double()> now_s;                        // default: steady clock
  std::function<void(const surfmap::v1::JobProgress&)> on_progress;  // after each accepted trace
  std::function<void(const std::string&)> on_event;     // notable events (failures, retries), one line each
};

class RigLoop {
 public:
  // `stop` may be null (never stops early). All references must outlive Run.
  RigLoop(ProbeEndpoint& endpoint, RigDriver& driver, RigLoopOptions options, const std::atomic<bool>* stop,
          RigLoopHooks hooks = {});

  // Runs until the job finishes, max_commands are executed, stop is set, or a
  // call fails for good (summary.error: a non-retryable error such as
  // NOT_FOUND or PERMISSION_DENIED, or retries exhausted).
  RigLoopSummary Run();

 private:
  enum class Step { kContinue, kEnd };

  bool Stopping() const { return stop_ != nullptr && stop_->load(); }
  void Event(const std::string& line);
  // Calls `call` until it is OK, not retryable, attempts run out or stop is
  // set while waiting. Returns the last status.
  grpc::Status WithRetries(const char* rpc, const std::function<grpc::Status()>& call);
  Step Fail(const char* rpc, const grpc::Status& status);
  Step RunCommand(const surfmap::v1::ProbeCommand& command);
  Step ReportFailure(const surfmap::v1::ProbeCommand& command, const std::string& reason);

  ProbeEndpoint& endpoint_;
  RigDriver& driver_;
  RigLoopOptions options_;
  const std::atomic<bool>* stop_;
  RigLoopHooks hooks_;
  RigLoopSummary summary_;
  // The lease a submission came back with (SubmitTrace lease_next): the next
  // command, without a LeaseCommand round trip.
  std::optional<surfmap::v1::LeaseCommandResponse> next_lease_;
};

}  // namespace surfmap::rig
