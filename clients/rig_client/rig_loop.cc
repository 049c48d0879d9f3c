#include "clients/rig_client/rig_loop.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <thread>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "clients/rig_client/probe_conversion.h"
#include "server/codec/trace_samples_proto.h"

namespace surfmap::rig {

namespace pb = ::surfmap::v1;

namespace {

bool IsFinitePositive(double v) { return std::isfinite(v) && v > 0; }

std::string Plural(int n, const char* one, const char* many) { return absl::StrCat(n, " ", n == 1 ? one : many); }

}  // namespace

bool RigLoopOptions::IsValid(std::string* why) const {
  auto fail = [why](const char* what) {
    if (why != nullptr) *why = what;
    return false;
  };
  if (rig_id.empty() || rig_id.size() > 100) return fail("rig_id must have 1..100 characters");
  if (job_id < 0) return fail("job_id must be >= 0");
  if (max_commands < 0) return fail("max_commands must be >= 0");
  if (max_attempts < 1) return fail("max_attempts must be >= 1");
  if (!IsFinitePositive(initial_backoff_s)) return fail("initial_backoff_s must be > 0");
  if (!IsFinitePositive(max_backoff_s) || max_backoff_s < initial_backoff_s) {
    return fail("max_backoff_s must be >= initial_backoff_s");
  }
  if (!IsFinitePositive(default_retry_after_s)) return fail("default_retry_after_s must be > 0");
  if (!IsFinitePositive(max_retry_after_s)) return fail("max_retry_after_s must be > 0");
  return true;
}

std::string RigLoopSummary::Format(const std::string& rig_id) const {
  std::string line = absl::StrFormat("%s: %s done, %s, %d abandoned, %s in %.1f s (%.2f traces/s)", rig_id,
                                     Plural(accepted, "command", "commands"), Plural(failures, "failure", "failures"),
                                     abandoned, Plural(retries, "retry", "retries"), elapsed_s, TracesPerSecond());
  if (job_finished) line += "; job finished";
  if (reached_max_commands) line += "; --max-commands reached";
  if (stopped) line += "; stopped by signal";
  if (!error.ok()) line += "; ended by an error";
  return line;
}

RigLoop::RigLoop(ProbeEndpoint& endpoint, RigDriver& driver, RigLoopOptions options, const std::atomic<bool>* stop,
                 RigLoopHooks hooks)
    : endpoint_(endpoint), driver_(driver), options_(std::move(options)), stop_(stop), hooks_(std::move(hooks)) {
  if (!hooks_.now_s) {
    hooks_.now_s = [] {
      return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
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
  grpc::Status status;
  for (int attempt = 1;; ++attempt) {
    status = call();
    if (status.ok() || !cli::IsRetryable(status.error_code()) || attempt >= options_.max_attempts) return status;
    Event(absl::StrFormat("%s (attempt %d of %d), retrying in %.1f s", cli::FormatRpcError(rpc, status, options_.rig_id),
                          attempt, options_.max_attempts, backoff));
    ++summary_.retries;
    hooks_.sleep(backoff);
    // Stop only interrupts waiting between attempts of a lease: a trace that
    // was measured is still worth delivering, so submissions keep trying.
    if (Stopping() && std::string_view(rpc) == "LeaseCommand") return status;
    backoff = std::min(backoff * 2.0, options_.max_backoff_s);
  }
}

RigLoop::Step RigLoop::Fail(const char* rpc, const grpc::Status& status) {
  summary_.error = status;
  summary_.error_rpc = rpc;
  return Step::kEnd;
}

RigLoop::Step RigLoop::ReportFailure(const pb::ProbeCommand& command, const std::string& reason) {
  pb::ReportFailureRequest request;
  request.set_command_id(command.command_id());
  request.set_rig_id(options_.rig_id);
  request.set_reason(reason.substr(0, 1000));
  pb::ReportFailureResponse response;
  grpc::Status status =
      WithRetries("ReportFailure", [&] { return endpoint_.ReportFailure(request, &response); });
  if (status.ok()) {
    ++summary_.failures;
    Event(absl::StrFormat("command %d (L%d v%d) failed%s: %s", command.command_id(), command.site().level(),
                          command.site().vertex(), response.will_retry() ? " (will be retried)" : "", reason));
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

RigLoop::Step RigLoop::RunCommand(const pb::ProbeCommand& command) {
  absl::StatusOr<ProbeRequest> request = ProbeRequestFromCommand(command);
  if (!request.ok()) return ReportFailure(command, std::string(request.status().message()));
  absl::StatusOr<DragTrace> trace = driver_.Execute(*request);
  if (!trace.ok()) {
    return ReportFailure(command, absl::StrCat("rig: ", absl::StatusCodeToString(trace.status().code()), ": ",
                                               trace.status().message()));
  }
  pb::SubmitTraceRequest submit;
  submit.set_command_id(command.command_id());
  submit.set_rig_id(options_.rig_id);
  // Ask for the next command with this answer unless this is the last one:
  // a lease nobody executes holds its site until the lease expires.
  const bool last = Stopping() || (options_.max_commands > 0 && summary_.executed() + 1 >= options_.max_commands);
  submit.set_lease_next(!last);
  *submit.mutable_samples() = DragTraceToProto(*trace);
  pb::SubmitTraceResponse response;
  grpc::Status status = WithRetries("SubmitTrace", [&] {
    response.Clear();
    return endpoint_.SubmitTrace(submit, &response);
  });
  if (status.ok()) {
    ++summary_.accepted;
    if (response.already_accepted()) ++summary_.already_accepted;
    if (response.has_next()) next_lease_ = response.next();
    if (hooks_.on_progress) hooks_.on_progress(response.progress());
    return Step::kContinue;
  }
  switch (status.error_code()) {
    case grpc::StatusCode::FAILED_PRECONDITION:
      // Lease expired and re-issued, or the job was paused/cancelled: the
      // next lease says what to do.
      ++summary_.abandoned;
      Event(cli::FormatRpcError("SubmitTrace", status, options_.rig_id));
      return Step::kContinue;
    case grpc::StatusCode::INVALID_ARGUMENT:
    case grpc::StatusCode::RESOURCE_EXHAUSTED:
      // The server cannot use this trace: let it retry the site.
      return ReportFailure(command, "trace rejected: " + std::string(cli::StatusCodeName(status.error_code())) +
                                                 ": " + status.error_message());
    default:
      return Fail("SubmitTrace", status);
  }
}

RigLoopSummary RigLoop::Run() {
  summary_ = RigLoopSummary();
  next_lease_.reset();
  const double start = hooks_.now_s();
  std::string why;
  if (!options_.IsValid(&why)) {
    summary_.error = grpc::Status(grpc::StatusCode::INVALID_ARGUMENT, "rig options: " + why);
    summary_.error_rpc = "options";
    return summary_;
  }
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
  summary_.elapsed_s = hooks_.now_s() - start;
  return summary_;
}

}  // namespace surfmap::rig
