#include "clients/rig/external_driver.h"

#include <cmath>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "clients/rig/driver_protocol.h"

namespace surfmap::rig {
namespace {

std::chrono::milliseconds Millis(double seconds) {
  return std::chrono::milliseconds(static_cast<long long>(std::llround(seconds * 1000.0)));
}

bool IsFinitePositive(double v) { return std::isfinite(v) && v > 0; }

}  // namespace

bool ExternalDriverOptions::IsValid(std::string* why) const {
  auto fail = [why](const char* what) {
    if (why != nullptr) *why = what;
    return false;
  };
  if (command.find_first_not_of(" \t") == std::string::npos) return fail("the driver command is empty");
  if (!IsFinitePositive(start_timeout_s)) return fail("driver start timeout must be > 0");
  if (!IsFinitePositive(command_timeout_s)) return fail("driver command timeout must be > 0");
  if (!(std::isfinite(exit_grace_s) && exit_grace_s >= 0)) return fail("driver exit grace must be >= 0");
  if (max_restarts < 0) return fail("driver max restarts must be >= 0");
  return true;
}

absl::StatusOr<std::unique_ptr<ExternalDriver>> ExternalDriver::Start(ExternalDriverOptions options) {
  std::string why;
  if (!options.IsValid(&why)) return absl::InvalidArgumentError(why);
  std::unique_ptr<ExternalDriver> driver(new ExternalDriver(std::move(options)));
  if (absl::Status launched = driver->Launch(); !launched.ok()) return launched;
  return driver;
}

ExternalDriver::~ExternalDriver() {
  if (process_) {
    const std::string how = process_->Stop(Millis(options_.exit_grace_s), [this](const std::string& line) {
      absl::StatusOr<DriverReply> reply = ParseDriverReply(line, 0);
      if (reply.ok() && reply->type == DriverReply::Type::kLog) {
        Log(absl::StrCat("driver: ", reply->message));
      } else {
        Log(absl::StrCat("driver wrote after its last command: ", line.substr(0, 200)));
      }
    });
    Log(absl::StrCat("driver ", how.empty() ? std::string("stopped") : how));
  }
}

void ExternalDriver::Log(const std::string& line) const {
  if (options_.on_log) options_.on_log(line);
}

absl::Status ExternalDriver::Launch() {
  ++starts_;
  absl::StatusOr<std::unique_ptr<DriverProcess>> process = DriverProcess::Start(options_.command);
  if (!process.ok()) return process.status();
  process_ = std::move(*process);
  const auto deadline = DriverProcess::Clock::now() + Millis(options_.start_timeout_s);
  while (true) {
    absl::StatusOr<std::string> line = process_->ReadLine(deadline);
    if (!line.ok()) {
      const absl::Status status = line.status();
      std::string how = process_->Stop(std::chrono::milliseconds(0));
      process_.reset();
      if (status.code() == absl::StatusCode::kDeadlineExceeded) {
        return absl::DeadlineExceededError(absl::StrFormat(
            "driver '%s' wrote no ready line within %.0f s (stopped: it %s)", options_.command,
            options_.start_timeout_s, how));
      }
      if (status.code() == absl::StatusCode::kUnavailable) {
        return absl::UnavailableError(absl::StrFormat("driver '%s' %s before its ready line%s", options_.command,
                                                      how.empty() ? "ended" : how,
                                                      how == "exited with code 127" ? " (command not found?)" : ""));
      }
      return absl::InternalError(absl::StrFormat("driver '%s': %s", options_.command, status.message()));
    }
    // A log line may come before ready (e.g. while the robot homes).
    absl::StatusOr<DriverReply> log = ParseDriverReply(*line, 0);
    if (log.ok() && log->type == DriverReply::Type::kLog) {
      Log(absl::StrCat("driver: ", log->message));
      continue;
    }
    absl::StatusOr<DriverReady> ready = ParseReadyMessage(*line);
    if (!ready.ok()) {
      process_->Stop(std::chrono::milliseconds(0));
      process_.reset();
      return absl::InternalError(
          absl::StrFormat("driver '%s' broke the protocol: %s", options_.command, ready.status().message()));
    }
    name_ = ready->driver;
    Log(absl::StrCat("driver ready: ", name_.empty() ? options_.command : name_));
    return absl::OkStatus();
  }
}

void ExternalDriver::Discard(const std::string& why) {
  if (!process_) return;
  const std::string how = process_->Stop(std::chrono::milliseconds(0));
  process_.reset();
  Log(absl::StrCat("driver stopped (", why, "; it ", how.empty() ? "ended" : how, ")"));
}

absl::StatusOr<DragTrace> ExternalDriver::Execute(const ProbeRequest& request) {
  if (!process_) {
    if (restarts_in_a_row_ >= options_.max_restarts) {
      return absl::InternalError(absl::StrCat("driver failed ", restarts_in_a_row_ + 1,
                                              " times in a row without a trace; not restarted"));
    }
    ++restarts_in_a_row_;
    Log(absl::StrCat("restarting the driver (", restarts_in_a_row_, " of at most ", options_.max_restarts,
                     " in a row)"));
    if (absl::Status launched = Launch(); !launched.ok()) {
      // Not answered by a trace: counts towards max_restarts.
      if (launched.code() == absl::StatusCode::kInternal) return launched;
      return absl::UnavailableError(launched.message());
    }
  }
  if (absl::Status written = process_->WriteLine(FormatCommandMessage(request)); !written.ok()) {
    Discard("it did not take the command");
    return absl::UnavailableError(absl::StrCat("driver: ", written.message()));
  }
  const auto deadline = DriverProcess::Clock::now() + Millis(options_.command_timeout_s);
  while (true) {
    absl::StatusOr<std::string> line = process_->ReadLine(deadline);
    if (!line.ok()) {
      if (line.status().code() == absl::StatusCode::kDeadlineExceeded) {
        Discard("no answer in time");
        return absl::DeadlineExceededError(absl::StrFormat(
            "driver did not answer command %d within %.0f s; it was stopped and a fresh one starts for the next "
            "command",
            request.command_id, options_.command_timeout_s));
      }
      if (line.status().code() == absl::StatusCode::kUnavailable) {
        const std::string how = process_->Stop(std::chrono::milliseconds(0));
        process_.reset();
        return absl::UnavailableError(absl::StrCat("the driver ", how.empty() ? "ended" : how,
                                                   " while measuring command ", request.command_id));
      }
      Discard("protocol error");
      return absl::InternalError(absl::StrCat("driver protocol: ", line.status().message()));
    }
    absl::StatusOr<DriverReply> reply = ParseDriverReply(*line, request.command_id);
    if (!reply.ok()) {
      Discard("protocol error");
      return absl::InternalError(absl::StrCat("driver protocol: ", reply.status().message()));
    }
    switch (reply->type) {
      case DriverReply::Type::kLog:
        Log(absl::StrCat("driver: ", reply->message));
        continue;
      case DriverReply::Type::kTrace:
        restarts_in_a_row_ = 0;
        return std::move(reply->trace);
      case DriverReply::Type::kFailure:
        // The driver answered: it works, whatever the site.
        restarts_in_a_row_ = 0;
        if (reply->stop) return absl::AbortedError(reply->reason);
        if (reply->kind == surfmap::v1::FAILURE_KIND_UNREACHABLE) return absl::FailedPreconditionError(reply->reason);
        return absl::UnavailableError(reply->reason);
    }
  }
}

}  // namespace surfmap::rig
