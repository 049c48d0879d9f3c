#include "clients/rig/driver_process.h"

#include <fcntl.h>
#include <poll.h>
#include <pthread.h>
#include <signal.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <thread>

#include "absl/strings/str_cat.h"

namespace surfmap::rig {
namespace {

std::string Describe(int status) {
  if (WIFEXITED(status)) return absl::StrCat("exited with code ", WEXITSTATUS(status));
  if (WIFSIGNALED(status)) {
    const char* name = sigabbrev_np(WTERMSIG(status));
    return absl::StrCat("was killed by signal ", WTERMSIG(status), name ? absl::StrCat(" (SIG", name, ")") : "");
  }
  return "ended";
}

// write(2) with SIGPIPE blocked for this thread, and a SIGPIPE it raised
// consumed before unblocking, so a dead reader gives EPIPE and never kills
// the rig (without changing the process's signal disposition).
ssize_t WriteWithoutSigpipe(int fd, const char* data, size_t size) {
  sigset_t pipe_only, old;
  sigemptyset(&pipe_only);
  sigaddset(&pipe_only, SIGPIPE);
  sigset_t pending;
  sigemptyset(&pending);
  pthread_sigmask(SIG_BLOCK, &pipe_only, &old);
  const bool was_pending = sigpending(&pending) == 0 && sigismember(&pending, SIGPIPE);
  ssize_t n;
  do {
    n = ::write(fd, data, size);
  } while (n < 0 && errno == EINTR);
  const int error = errno;
  if (n < 0 && error == EPIPE && !was_pending) {
    const timespec zero{0, 0};
    while (sigtimedwait(&pipe_only, nullptr, &zero) < 0 && errno == EINTR) {
    }
  }
  pthread_sigmask(SIG_SETMASK, &old, nullptr);
  errno = error;
  return n;
}

}  // namespace

absl::StatusOr<std::unique_ptr<DriverProcess>> DriverProcess::Start(const std::string& command) {
  int to_child[2], from_child[2];
  if (::pipe2(to_child, O_CLOEXEC) != 0) return absl::InternalError(absl::StrCat("pipe: ", strerror(errno)));
  if (::pipe2(from_child, O_CLOEXEC) != 0) {
    const int error = errno;
    ::close(to_child[0]);
    ::close(to_child[1]);
    return absl::InternalError(absl::StrCat("pipe: ", strerror(error)));
  }
  const pid_t pid = ::fork();
  if (pid < 0) {
    const int error = errno;
    for (int fd : {to_child[0], to_child[1], from_child[0], from_child[1]}) ::close(fd);
    return absl::InternalError(absl::StrCat("fork: ", strerror(error)));
  }
  if (pid == 0) {
    // Only async-signal-safe calls until exec.
    ::setpgid(0, 0);
    ::dup2(to_child[0], STDIN_FILENO);   // dup2 clears O_CLOEXEC on the copies
    ::dup2(from_child[1], STDOUT_FILENO);
    // Default signal handling and mask for the program, whatever the rig set.
    sigset_t none;
    sigemptyset(&none);
    ::sigprocmask(SIG_SETMASK, &none, nullptr);
    ::signal(SIGPIPE, SIG_DFL);
    ::signal(SIGINT, SIG_DFL);
    ::signal(SIGTERM, SIG_DFL);
    ::execl("/bin/sh", "sh", "-c", command.c_str(), static_cast<char*>(nullptr));
    const char message[] = "surfmap-rig: cannot run /bin/sh for the driver\n";
    (void)!::write(STDERR_FILENO, message, sizeof message - 1);
    ::_exit(127);
  }
  ::setpgid(pid, pid);  // also here: no race with a signal sent to the group right after fork
  ::close(to_child[0]);
  ::close(from_child[1]);
  return std::unique_ptr<DriverProcess>(new DriverProcess(pid, to_child[1], from_child[0]));
}

DriverProcess::~DriverProcess() { Stop(std::chrono::seconds(10)); }

bool DriverProcess::Exited() {
  if (exited_) return true;
  int status = 0;
  const pid_t done = ::waitpid(pid_, &status, WNOHANG);
  if (done == pid_) {
    exited_ = true;
    exit_description_ = Describe(status);
  }
  return exited_;
}

bool DriverProcess::WaitForExit(std::chrono::milliseconds timeout) {
  const Clock::time_point deadline = Clock::now() + timeout;
  while (!Exited()) {
    if (Clock::now() >= deadline) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return true;
}

absl::Status DriverProcess::WriteLine(std::string_view line) {
  if (to_child_ < 0) return absl::FailedPreconditionError("the driver's stdin is closed");
  std::string data(line);
  data.push_back('\n');
  size_t written = 0;
  while (written < data.size()) {
    const ssize_t n = WriteWithoutSigpipe(to_child_, data.data() + written, data.size() - written);
    if (n < 0) {
      if (errno == EPIPE) {
        WaitForExit(std::chrono::milliseconds(1000));
        return absl::UnavailableError(absl::StrCat(
            "the driver no longer reads its stdin (it ",
            exited_ ? exit_description_ : std::string("closed stdin but is still running"), ")"));
      }
      return absl::InternalError(absl::StrCat("writing to the driver: ", strerror(errno)));
    }
    written += static_cast<size_t>(n);
  }
  return absl::OkStatus();
}

absl::StatusOr<std::string> DriverProcess::ReadLine(Clock::time_point deadline) {
  while (true) {
    const size_t newline = buffer_.find('\n');
    if (newline != std::string::npos) {
      std::string line = buffer_.substr(0, newline);
      buffer_.erase(0, newline + 1);
      if (!line.empty() && line.back() == '\r') line.pop_back();
      return line;
    }
    if (buffer_.size() > kMaxLineBytes) {
      return absl::InvalidArgumentError(absl::StrCat("the driver wrote a line longer than ", kMaxLineBytes, " bytes"));
    }
    if (from_child_ < 0) return absl::UnavailableError("the driver's stdout is closed");
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now()).count();
    if (left <= 0) return absl::DeadlineExceededError("no line from the driver in time");
    pollfd fd{from_child_, POLLIN, 0};
    const int ready = ::poll(&fd, 1, static_cast<int>(std::min<long long>(left, 1000)));
    if (ready < 0 && errno != EINTR) return absl::InternalError(absl::StrCat("poll: ", strerror(errno)));
    if (ready <= 0) continue;
    char chunk[65536];
    const ssize_t n = ::read(from_child_, chunk, sizeof chunk);
    if (n < 0 && (errno == EINTR || errno == EAGAIN)) continue;
    if (n < 0) return absl::InternalError(absl::StrCat("reading from the driver: ", strerror(errno)));
    if (n == 0) {
      // End of its stdout: it exited (or closed it, which the protocol does not allow).
      ::close(from_child_);
      from_child_ = -1;
      WaitForExit(std::chrono::milliseconds(2000));
      return absl::UnavailableError(exited_ ? absl::StrCat("the driver ", exit_description_)
                                            : std::string("the driver closed its stdout"));
    }
    buffer_.append(chunk, static_cast<size_t>(n));
  }
}

std::string DriverProcess::Stop(std::chrono::milliseconds grace,
                                const std::function<void(const std::string&)>& on_line) {
  if (to_child_ >= 0) {
    ::close(to_child_);
    to_child_ = -1;
  }
  const Clock::time_point grace_end = Clock::now() + grace;
  // What it says while it winds down (e.g. "robot parked"), until it closes stdout.
  while (on_line && from_child_ >= 0 && Clock::now() < grace_end) {
    absl::StatusOr<std::string> line = ReadLine(grace_end);
    if (!line.ok()) break;
    on_line(*line);
  }
  const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(grace_end - Clock::now());
  if (!WaitForExit(std::max(left, std::chrono::milliseconds(0)))) {
    ::kill(-pid_, SIGTERM);
    if (!WaitForExit(std::chrono::seconds(5))) {
      ::kill(-pid_, SIGKILL);
      WaitForExit(std::chrono::seconds(5));
    }
  }
  if (from_child_ >= 0) {
    ::close(from_child_);
    from_child_ = -1;
  }
  return exit_description_;
}

}  // namespace surfmap::rig
