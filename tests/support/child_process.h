// ChildProcess: a client binary (surfmap-rig, ...) run by an integration test
// as a real process, its stdout and stderr captured to one file.
//
// The child gets PR_SET_PDEATHSIG = SIGKILL (a crashed test leaves nothing
// behind; as with ServerProcess, start it from the test's main thread), and
// the destructor SIGKILLs one still running.
#pragma once

#include <sys/types.h>

#include <chrono>
#include <memory>
#include <string>
#include <vector>

#include "absl/status/statusor.h"

namespace surfmap::itest {

class ChildProcess {
 public:
  // Starts argv[0] (a path) with `argv`, output to `log_path`. INTERNAL when
  // it cannot be started.
  static absl::StatusOr<std::unique_ptr<ChildProcess>> Start(std::vector<std::string> argv,
                                                             const std::string& log_path);
  ~ChildProcess();
  ChildProcess(const ChildProcess&) = delete;
  ChildProcess& operator=(const ChildProcess&) = delete;

  // Waits for the exit code (128 + signal when killed by a signal).
  // DEADLINE_EXCEEDED (with the output) when it is still running after
  // `timeout`; the process is then killed.
  absl::StatusOr<int> Wait(std::chrono::milliseconds timeout);
  bool running() const { return pid_ > 0; }
  // Everything it wrote so far.
  std::string Output() const;
  std::string command_line() const { return command_line_; }

 private:
  ChildProcess(pid_t pid, std::string log_path, std::string command_line)
      : pid_(pid), log_path_(std::move(log_path)), command_line_(std::move(command_line)) {}

  pid_t pid_;
  std::string log_path_;
  std::string command_line_;
};

}  // namespace surfmap::itest
