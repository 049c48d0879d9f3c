// ExternalDriver: a RigDriver that runs a lab's own driver program and
// speaks the JSON-lines protocol of driver_protocol.h with it, so a robot can
// be driven from any language without rebuilding surfmap-rig.
//
// Lifecycle: Start runs the program and waits for its ready line. Execute
// sends one command and waits for its answer (log lines in between are
// passed on). When the program does not answer in time it is stopped
// (SIGTERM to its process group) and the command fails TRANSIENT; when it
// dies the command fails TRANSIENT; either way a fresh one is started for the
// next command, up to max_restarts times in a row without a trace, after
// which Execute answers INTERNAL (the rig stops). A protocol violation
// (not JSON, a wrong command id, a malformed trace, ...) is INTERNAL at once:
// the rig reports the command as failed and stops, naming the problem.
// The destructor closes the program's stdin (no more commands) and waits for
// it to exit (exit_grace, then SIGTERM, then SIGKILL).
#pragma once

#include <chrono>
#include <functional>
#include <memory>
#include <string>

#include "absl/status/statusor.h"
#include "clients/sim/rig/rig_driver.h"
#include "clients/rig/driver_process.h"

namespace surfmap::rig {

struct ExternalDriverOptions {
  std::string command;            // run as /bin/sh -c COMMAND
  double start_timeout_s = 60.0;  // until its ready line (homing a robot takes a while)
  double command_timeout_s = 120.0;  // per command, until its trace or failure
  double exit_grace_s = 10.0;     // after stdin is closed, before SIGTERM
  int max_restarts = 3;           // fresh starts in a row without a trace before giving up
  std::function<void(const std::string&)> on_log;  // the driver's log lines and restarts, one line each

  // False (and *why) for an empty command or non-positive times / counts.
  bool IsValid(std::string* why) const;
};

class ExternalDriver : public RigDriver {
 public:
  // Starts the program and waits for its ready line. INVALID_ARGUMENT for
  // bad options; UNAVAILABLE when it exits first (with its exit code);
  // DEADLINE_EXCEEDED when it says nothing within start_timeout_s;
  // INTERNAL when its first line is not a ready message of protocol 1.
  static absl::StatusOr<std::unique_ptr<ExternalDriver>> Start(ExternalDriverOptions options);

  ~ExternalDriver() override;

  absl::StatusOr<DragTrace> Execute(const ProbeRequest& request) override;

  // What the driver called itself in its ready line.
  const std::string& name() const { return name_; }
  // Starts so far, the first included.
  int starts() const { return starts_; }

 private:
  explicit ExternalDriver(ExternalDriverOptions options) : options_(std::move(options)) {}
  // Starts the program and reads its ready line.
  absl::Status Launch();
  // Stops a program that misbehaved; the next Execute starts a fresh one.
  void Discard(const std::string& why);
  void Log(const std::string& line) const;

  ExternalDriverOptions options_;
  std::unique_ptr<DriverProcess> process_;
  std::string name_;
  int starts_ = 0;
  int restarts_in_a_row_ = 0;
};

}  // namespace surfmap::rig
