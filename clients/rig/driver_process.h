// DriverProcess: an external driver program as a child process that the rig
// talks to in lines: its stdin and stdout are pipes, its stderr is the rig's.
//
// The program runs as `/bin/sh -c COMMAND` in a process group of its own, so
// a Ctrl-C at the terminal reaches only surfmap-rig (which finishes the
// command being measured, then closes the driver's stdin). Writing to a
// driver that has exited is an error, not a SIGPIPE for the rig.
#pragma once

#include <sys/types.h>

#include <chrono>
#include <functional>
#include <memory>
#include <string>
#include <string_view>

#include "absl/status/statusor.h"

namespace surfmap::rig {

class DriverProcess {
 public:
  using Clock = std::chrono::steady_clock;

  // Lines longer than this are a protocol error (a trace of 100k samples is
  // about 16 MB).
  static constexpr size_t kMaxLineBytes = 64u << 20;

  // Starts `/bin/sh -c command`. INTERNAL when it cannot be started (an
  // unknown program shows as an exit with code 127 on the first read).
  static absl::StatusOr<std::unique_ptr<DriverProcess>> Start(const std::string& command);

  ~DriverProcess();  // Stop(10 s)
  DriverProcess(const DriverProcess&) = delete;
  DriverProcess& operator=(const DriverProcess&) = delete;

  // Writes `line` and a newline. UNAVAILABLE when the program no longer
  // reads (it exited: the message says how).
  absl::Status WriteLine(std::string_view line);

  // The next line (without the newline). DEADLINE_EXCEEDED at `deadline`;
  // UNAVAILABLE when the program closed its stdout (exited: the message says
  // how, e.g. "exited with code 3"); INVALID_ARGUMENT for a line beyond
  // kMaxLineBytes.
  absl::StatusOr<std::string> ReadLine(Clock::time_point deadline);

  // Ends the program: closes its stdin (the protocol's "no more commands"),
  // waits up to `grace` for it to exit (passing the lines it still writes to
  // `on_line`, when given), then SIGTERM to its process group, 5 s later
  // SIGKILL. Returns how it ended ("exited with code 0"). Idempotent.
  std::string Stop(std::chrono::milliseconds grace,
                   const std::function<void(const std::string&)>& on_line = nullptr);

  // Whether the program has exited (reaps it; never blocks).
  bool Exited();
  // How it ended, once Exited(): "exited with code N" / "was killed by signal N (NAME)".
  const std::string& exit_description() const { return exit_description_; }
  pid_t pid() const { return pid_; }

 private:
  DriverProcess(pid_t pid, int to_child, int from_child) : pid_(pid), to_child_(to_child), from_child_(from_child) {}
  // Waits up to `timeout` for the exit; true when it has exited.
  bool WaitForExit(std::chrono::milliseconds timeout);

  pid_t pid_;
  int to_child_;
  int from_child_;
  bool exited_ = false;
  std::string exit_description_;
  std::string buffer_;  // read but not yet returned
};

}  // namespace surfmap::rig
