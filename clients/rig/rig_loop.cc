#include "clients/rig/rig_loop.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <thread>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "clients/rig/control_characters.h"
#include "clients/rig/probe_conversion.h"
#include "server/codec/rig_registration_proto.h"
#include "server/codec/trace_samples_proto.h"

namespace surfmap::rig {

namespace pb = ::surfmap::v1;
namespace fs = std::filesystem;

namespace {

bool IsFinitePositive(double v) { return std::isfinite(v) && v > 0; }

std::string Plural(int n, const char* one, const char* many) { return absl::StrCat(n, " ", n == 1 ? one : many); }

grpc::Status ToGrpc(const absl::Status& status) {
  return grpc::Status(static_cast<grpc::StatusCode>(static_cast<int>(status.code())), std::string(status.message()));
}

std::string CodeAndMessage(const grpc::Status& status) {
  return std::string(cli::StatusCodeName(status.error_code())) + ": " + status.error_message();
}

// A submission the server refused for good: resubmitting cannot change the answer.
bool IsDefinitiveRefusal(grpc::StatusCode code) {
  switch (code) {
    case grpc::StatusCode::ALREADY_EXISTS:       // another rig measured the command
    case grpc::StatusCode::FAILED_PRECONDITION:  // lease lost, job paused/cancelled/completed
    case grpc::StatusCode::NOT_FOUND:            // no such command on this server
    case grpc::StatusCode::INVALID_ARGUMENT:     // the server cannot use the trace
    case grpc::StatusCode::RESOURCE_EXHAUSTED:   // the trace is too large for the server
      return true;
    default:
      return false;
  }
}

}  // namespace

bool RigLoopOptions::IsValid(std::string* why) const {
  auto fail = [why](const char* what) {
    if (why != nullptr) *why = what;
    return false;
  };
  if (rig_id.empty() || rig_id.size() > 100) return fail("rig_id must have 1..100 characters");
  if (HasControlCharacter(rig_id)) return fail("rig_id must not contain control characters (newline, tab, ...)");
  if (job_id < 0) return fail("job_id must be >= 0");
  if (max_commands < 0) return fail("max_commands must be >= 0");
  if (!(std::isfinite(retry_for_s) && retry_for_s >= 0)) return fail("retry_for_s must be >= 0");
  if (!IsFinitePositive(initial_backoff_s)) return fail("initial_backoff_s must be > 0");
  if (!IsFinitePositive(max_backoff_s) || max_backoff_s < initial_backoff_s) {
    return fail("max_backoff_s must be >= initial_backoff_s");
  }
  if (!IsFinitePositive(default_retry_after_s)) return fail("default_retry_after_s must be > 0");
  if (!IsFinitePositive(max_retry_after_s)) return fail("max_retry_after_s must be > 0");
  if (!TraceFrameFromProto(frame).ok()) return fail("frame must be a TraceFrame value");
  return true;
}

std::string RigLoopSummary::Format(const std::string& rig_id) const {
  std::string line = absl::StrFormat("%s: %s done, %s, %d abandoned, %s in %.1f s (%.2f traces/s)", rig_id,
                                     Plural(accepted, "command", "commands"), Plural(failures, "failure", "failures"),
                                     abandoned, Plural(retries, "retry", "retries"), elapsed_s, TracesPerSecond());
  if (resubmitted > 0) absl::StrAppend(&line, "; ", Plural(resubmitted, "spooled trace", "spooled traces"), " resubmitted");
  if (rejected > 0) absl::StrAppend(&line, "; ", Plural(rejected, "trace", "traces"), " rejected");
  if (spooled_left > 0) absl::StrAppend(&line, "; ", Plural(spooled_left, "trace", "traces"), " left in the spool");
  if (job_finished) line += "; job finished";
  if (reached_max_commands) line += "; --max-commands reached";
  if (stopped) line += "; stopped by signal";
  if (!error.ok()) line += "; ended by an error";
  return line;
}

std::string FormatWaitDuration(double seconds) {
  if (!(seconds > 0)) return "0 s";
  if (seconds < 10) return absl::StrFormat("%.1f s", seconds);
  const long long whole = std::llround(seconds);
  if (whole < 60) return absl::StrFormat("%d s", whole);
  if (whole < 3600) {
    return whole % 60 == 0 ? absl::StrFormat("%d min", whole / 60)
                           : absl::StrFormat("%d min %d s", whole / 60, whole % 60);
  }
  const long long minutes = (whole % 3600) / 60;
  return minutes == 0 ? absl::StrFormat("%d h", whole / 3600) : absl::StrFormat("%d h %d min", whole / 3600, minutes);
}

std::string FormatRetryNotice(const RetryNotice& notice) {
  const char* what = notice.status.error_code() == grpc::StatusCode::DEADLINE_EXCEEDED ? "server not answering"
                                                                                       : "server unavailable";
  return absl::StrFormat("%s, retrying for %s (%s: %s)", what, FormatWaitDuration(notice.remaining_s), notice.rpc,
                         CodeAndMessage(notice.status));
}

pb::FailureKind FailureKindOf(const absl::Status& driver_error) {
  switch (driver_error.code()) {
    case absl::StatusCode::kFailedPrecondition:
    case absl::StatusCode::kOutOfRange:
      return pb::FAILURE_KIND_UNREACHABLE;
    default:
      return pb::FAILURE_KIND_TRANSIENT;
  }
}

RigLoop::RigLoop(ProbeEndpoint& endpoint, RigDriver& driver, TraceSpool& spool, RigLoopOptions options,
                 const std::atomic<bool>* stop, RigLoopHooks hooks)
    : endpoint_(endpoint),
      driver_(driver),
      spool_(spool),
      options_(std::move(options)),
      stop_(stop),
      hooks_(std::move(hooks)) {
  if (!hooks_.now_s) {
    hooks_.now_s = [] {
      return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
    };
  }
  if (!hooks_.unix_ms) {
    hooks_.unix_ms = [] {
      return static_cast<std::int64_t>(std::chrono::duration_cast<std::chrono::milliseconds>(
                                           std::chrono::system_clock::now().time_since_epoch())
                                           .count());
    };
  }
  if (!hooks_.sleep) {
    const std::atomic<bool>* flag = stop_;
    hooks_.sleep = [flag](double seconds) {
      // Slices of 50 ms so a signal ends the wait promptly.
      const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
      while (std::chrono::steady_clock::now() < end && !(flag != nullptr && flag->load())) {
        const auto left = std::chrono::duration_cast<std::chrono::steady_clock::duration>(
            end - std::chrono::steady_clock::now());
        std::this_thread::sleep_for(
            std::min<std::chrono::steady_clock::duration>(std::chrono::milliseconds(50), left));
      }
    };
  }
}

void RigLoop::Event(const std::string& line) {
  if (hooks_.on_event) hooks_.on_event(line);
}

grpc::Status RigLoop::WithRetries(const char* rpc, const std::function<grpc::Status()>& call) {
  double backoff = options_.initial_backoff_s;
  double first_failure_s = -1.0;
  for (int attempt = 1;; ++attempt) {
    grpc::Status status = call();
    if (status.ok() || !cli::IsRetryable(status.error_code())) return status;
    const double now = hooks_.now_s();
    if (first_failure_s < 0) first_failure_s = now;
    const double left = options_.retry_for_s - (now - first_failure_s);
    if (left <= 0) {
      Event(absl::StrFormat("%s; gave up after retrying for %s", cli::FormatRpcError(rpc, status, options_.rig_id),
                            FormatWaitDuration(options_.retry_for_s)));
      return status;
    }
    RetryNotice notice{rpc, status, attempt, std::min(backoff, left), left};
    ++summary_.retries;
    if (hooks_.on_retry) {
      hooks_.on_retry(notice);
    } else {
      Event(absl::StrCat(options_.rig_id, ": ", FormatRetryNotice(notice)));
    }
    hooks_.sleep(notice.wait_s);
    // Stop only interrupts waiting between attempts of a lease: a trace that
    // was measured is still worth delivering, so submissions keep trying (a
    // second signal leaves at once; the trace is in the spool).
    if (Stopping() && std::string_view(rpc) == "LeaseCommand") return status;
    backoff = std::min(backoff * 2.0, options_.max_backoff_s);
  }
}

RigLoop::Step RigLoop::Fail(const char* rpc, const grpc::Status& status) {
  summary_.error = status;
  summary_.error_rpc = rpc;
  return Step::kEnd;
}

RigLoop::Step RigLoop::ReportFailure(std::int64_t command_id, const std::string& where, const std::string& reason,
                                     pb::FailureKind kind) {
  pb::ReportFailureRequest request;
  request.set_command_id(command_id);
  request.set_rig_id(options_.rig_id);
  request.set_reason(reason.substr(0, 1000));
  request.set_kind(kind);
  pb::ReportFailureResponse response;
  grpc::Status status =
      WithRetries("ReportFailure", [&] { return endpoint_.ReportFailure(request, &response); });
  if (status.ok()) {
    ++summary_.failures;
    Event(absl::StrFormat("%s: %s failed (%s%s): %s", options_.rig_id, where,
                          kind == pb::FAILURE_KIND_UNREACHABLE ? "unreachable" : "transient",
                          response.will_retry() ? ", will be retried" : "", reason));
    return Step::kContinue;
  }
  if (status.error_code() == grpc::StatusCode::FAILED_PRECONDITION ||
      status.error_code() == grpc::StatusCode::NOT_FOUND) {
    // The lease was lost or the job ended: nothing left to report to.
    ++summary_.abandoned;
    Event(cli::FormatRpcError("ReportFailure", status, options_.rig_id));
    return Step::kContinue;
  }
  return Fail("ReportFailure", status);
}

RigLoop::Delivery RigLoop::Deliver(const fs::path& file, const SpooledTrace& spooled, bool lease_next) {
  pb::SubmitTraceRequest submit;
  submit.set_command_id(spooled.header.command_id);
  submit.set_rig_id(spooled.header.rig_id);  // the rig that held the lease (this one, unless --spool was shared)
  submit.set_lease_next(lease_next);
  // The frame the trace was measured in, not this run's: a trace spooled by
  // a --frame rig_base run and resubmitted by a default run is still in the
  // rig's frame.
  submit.set_frame(TraceFrameToProto(spooled.header.frame));
  submit.set_registration_id(spooled.header.registration_id);
  *submit.mutable_samples() = DragTraceToProto(spooled.trace);
  pb::SubmitTraceResponse response;
  grpc::Status status = WithRetries("SubmitTrace", [&] {
    response.Clear();
    return endpoint_.SubmitTrace(submit, &response);
  });
  if (status.ok()) {
    if (absl::Status removed = spool_.Remove(file); !removed.ok()) {
      // Harmless: resubmitting it later is answered already_accepted.
      Event(absl::StrCat(options_.rig_id, ": accepted, but the spooled copy stays: ", removed.message()));
    }
    if (response.already_accepted()) ++summary_.already_accepted;
    if (response.has_next()) next_lease_ = response.next();
    if (hooks_.on_progress) hooks_.on_progress(response.progress());
    return Delivery::kAccepted;
  }
  if (IsDefinitiveRefusal(status.error_code())) {
    absl::StatusOr<fs::path> moved = spool_.Reject(file, absl::StrCat("SubmitTrace: ", CodeAndMessage(status)));
    if (!moved.ok()) {
      Fail("spool", ToGrpc(moved.status()));
      return Delivery::kKept;
    }
    ++summary_.rejected;
    Event(absl::StrFormat("%s; trace kept in %s", cli::FormatRpcError("SubmitTrace", status, options_.rig_id),
                          moved->string()));
    last_refusal_ = status;
    const bool unusable = status.error_code() == grpc::StatusCode::INVALID_ARGUMENT ||
                          status.error_code() == grpc::StatusCode::RESOURCE_EXHAUSTED;
    return unusable ? Delivery::kUnusable : Delivery::kRefused;
  }
  Fail("SubmitTrace", status);
  Event(absl::StrFormat("%s: the trace for command %d stays in %s: it is resubmitted when the rig starts again",
                        options_.rig_id, spooled.header.command_id, file.string()));
  return Delivery::kKept;
}

RigLoop::Step RigLoop::ResubmitSpool() {
  absl::StatusOr<std::vector<fs::path>> files = spool_.Pending();
  if (!files.ok()) return Fail("spool", ToGrpc(files.status()));
  if (files->empty()) return Step::kContinue;
  Event(absl::StrFormat("%s: resubmitting %s from %s", options_.rig_id,
                        Plural(static_cast<int>(files->size()), "spooled trace", "spooled traces"),
                        spool_.dir().string()));
  for (const fs::path& file : *files) {
    absl::StatusOr<SpooledTrace> spooled = spool_.Read(file);
    if (!spooled.ok()) {
      if (spooled.status().code() == absl::StatusCode::kNotFound) continue;
      absl::StatusOr<fs::path> moved = spool_.Reject(file, absl::StrCat("unreadable: ", spooled.status().message()));
      if (!moved.ok()) return Fail("spool", ToGrpc(moved.status()));
      ++summary_.rejected;
      Event(absl::StrFormat("%s: %s; moved to %s", options_.rig_id, spooled.status().message(), moved->string()));
      continue;
    }
    switch (Deliver(file, *spooled, /*lease_next=*/false)) {
      case Delivery::kAccepted:
        ++summary_.resubmitted;
        break;
      case Delivery::kRefused:
        break;
      case Delivery::kUnusable: {
        const int failures = summary_.failures;
        const Step step = ReportFailure(spooled->header.command_id, absl::StrCat("spooled command ", spooled->header.command_id),
                                        "trace rejected: " + CodeAndMessage(last_refusal_), pb::FAILURE_KIND_TRANSIENT);
        summary_.failures = failures;  // a failure of an earlier run: not one of this run's commands
        if (step == Step::kEnd) return step;
        break;
      }
      case Delivery::kKept:
        return Step::kEnd;
    }
  }
  return Step::kContinue;
}

RigLoop::Step RigLoop::RunCommand(const pb::ProbeCommand& command) {
  const std::string where = absl::StrFormat("command %d (L%d v%d)", command.command_id(), command.site().level(),
                                            command.site().vertex());
  absl::StatusOr<ProbeRequest> request = ProbeRequestFromCommand(command);
  if (!request.ok()) {
    return ReportFailure(command.command_id(), where, std::string(request.status().message()),
                         pb::FAILURE_KIND_TRANSIENT);
  }
  absl::StatusOr<DragTrace> trace = driver_.Execute(*request);
  if (!trace.ok()) {
    // The kind says what the code meant; the reason is the driver's own words.
    const Step step = ReportFailure(command.command_id(), where, absl::StrCat("rig: ", trace.status().message()),
                                    FailureKindOf(trace.status()));
    // INTERNAL: the driver itself is broken; ABORTED: its operator stopped it.
    if (trace.status().code() == absl::StatusCode::kInternal || trace.status().code() == absl::StatusCode::kAborted) {
      return Fail("driver", ToGrpc(trace.status()));
    }
    return step;
  }
  SpoolHeader header;
  header.command_id = command.command_id();
  header.job_id = command.job_id();
  header.attempt = command.attempt();
  header.rig_id = options_.rig_id;
  header.measured_unix_ms = hooks_.unix_ms();
  header.frame = TraceFrameFromProto(options_.frame).value_or(TraceFrame::kObject);  // IsValid checked it
  if (header.frame != TraceFrame::kObject && command.has_rig_frame()) {
    header.registration_id = command.rig_frame().registration_id();  // what the command was computed with
  }
  absl::StatusOr<fs::path> file = spool_.Add(header, *trace);
  if (!file.ok()) {
    if (file.status().code() == absl::StatusCode::kInvalidArgument) {
      ++summary_.rejected;  // Add kept it in rejected/
      return ReportFailure(command.command_id(), where, absl::StrCat("rig: invalid trace: ", file.status().message()),
                           pb::FAILURE_KIND_TRANSIENT);
    }
    // A rig that cannot keep its traces must not measure on: give the site
    // back and stop with the spool's error.
    ReportFailure(command.command_id(), where, absl::StrCat("rig cannot spool its trace: ", file.status().message()),
                  pb::FAILURE_KIND_TRANSIENT);
    return Fail("spool", ToGrpc(file.status()));
  }
  // Ask for the next command with this answer unless this is the last one:
  // a lease nobody executes holds its site until the lease expires.
  const bool last = Stopping() || (options_.max_commands > 0 && summary_.executed() + 1 >= options_.max_commands);
  const SpooledTrace spooled{std::move(header), *std::move(trace)};
  switch (Deliver(*file, spooled, !last)) {
    case Delivery::kAccepted:
      ++summary_.accepted;
      return Step::kContinue;
    case Delivery::kRefused:
      // Lease expired and re-issued or answered by another rig, or the job
      // was paused/cancelled: the next lease says what to do.
      ++summary_.abandoned;
      return Step::kContinue;
    case Delivery::kUnusable:
      // The server cannot use this trace: let it retry the site.
      return ReportFailure(command.command_id(), where, "trace rejected: " + CodeAndMessage(last_refusal_),
                           pb::FAILURE_KIND_TRANSIENT);
    case Delivery::kKept:
      return Step::kEnd;
  }
  return Step::kEnd;
}

RigLoopSummary RigLoop::Run() {
  summary_ = RigLoopSummary();
  next_lease_.reset();
  const double start = hooks_.now_s();
  auto finish = [&]() {
    absl::StatusOr<std::vector<fs::path>> left = spool_.Pending();
    summary_.spooled_left = left.ok() ? static_cast<int>(left->size()) : -1;
    summary_.elapsed_s = hooks_.now_s() - start;
    return summary_;
  };
  std::string why;
  if (!options_.IsValid(&why)) {
    summary_.error = grpc::Status(grpc::StatusCode::INVALID_ARGUMENT, "rig options: " + why);
    summary_.error_rpc = "options";
    return summary_;
  }
  if (ResubmitSpool() == Step::kEnd) return finish();
  pb::LeaseCommandRequest lease;
  lease.set_rig_id(options_.rig_id);
  lease.set_job_id(options_.job_id);
  while (true) {
    if (Stopping()) {
      summary_.stopped = true;
      break;
    }
    if (options_.max_commands > 0 && summary_.executed() >= options_.max_commands) {
      summary_.reached_max_commands = true;
      break;
    }
    pb::LeaseCommandResponse response;
    grpc::Status status = grpc::Status::OK;
    if (next_lease_) {
      response = std::move(*next_lease_);
      next_lease_.reset();
    } else {
      status = WithRetries("LeaseCommand", [&] {
        response.Clear();
        return endpoint_.LeaseCommand(lease, &response);
      });
    }
    if (!status.ok()) {
      if (Stopping()) continue;  // gave up waiting because of the stop request
      Fail("LeaseCommand", status);
      break;
    }
    if (response.job_finished()) {
      summary_.job_finished = true;
      break;
    }
    if (response.has_command() && response.command().command_id() != 0) {
      if (RunCommand(response.command()) == Step::kEnd) break;
      continue;
    }
    double wait = options_.default_retry_after_s;
    if (response.has_retry_after()) {
      const double s = static_cast<double>(response.retry_after().seconds()) + response.retry_after().nanos() * 1e-9;
      if (s > 0) wait = s;
    }
    hooks_.sleep(std::min(wait, options_.max_retry_after_s));
  }
  return finish();
}

}  // namespace surfmap::rig
