#include "tests/support/server_process.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>
#include <thread>

#include <grpcpp/create_channel.h>
#include <grpcpp/security/credentials.h>
#include <grpcpp/support/channel_arguments.h>
#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "absl/strings/strip.h"

#ifndef SURFMAPD_PATH
#define SURFMAPD_PATH "surfmapd"
#endif

namespace surfmap::itest {
namespace {

using Clock = std::chrono::steady_clock;

std::string ReadWholeFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

// The port file holds the port, maybe as "host:port", maybe with a newline.
bool ParsePortFile(const std::string& text, int* port) {
  absl::string_view view = absl::StripAsciiWhitespace(text);
  if (size_t colon = view.rfind(':'); colon != absl::string_view::npos) view.remove_prefix(colon + 1);
  return absl::SimpleAtoi(view, port) && *port > 0 && *port < 65536;
}

}  // namespace

std::string DefaultSurfmapdPath() {
  if (const char* env = std::getenv("SURFMAPD"); env != nullptr && env[0] != '\0') return env;
  return SURFMAPD_PATH;
}

std::shared_ptr<grpc::Channel> MakeChannel(const std::string& address, bool own_subchannel) {
  grpc::ChannelArguments args;
  args.SetMaxReceiveMessageSize(512 << 20);
  args.SetMaxSendMessageSize(-1);
  if (own_subchannel) args.SetInt(GRPC_ARG_USE_LOCAL_SUBCHANNEL_POOL, 1);
  return grpc::CreateCustomChannel(address, grpc::InsecureChannelCredentials(), args);
}

std::shared_ptr<grpc::Channel> ConnectedChannel(const std::string& address, bool own_subchannel) {
  std::shared_ptr<grpc::Channel> channel = MakeChannel(address, own_subchannel);
  // Not connecting is left to the first call to report, with its reason.
  channel->WaitForConnected(std::chrono::system_clock::now() + std::chrono::seconds(20));
  return channel;
}

absl::StatusOr<std::unique_ptr<ServerProcess>> ServerProcess::Start(ServerOptions options) {
  if (access(options.binary.c_str(), X_OK) != 0) {
    return absl::FailedPreconditionError(
        absl::StrCat("surfmapd binary '", options.binary, "' is not executable: ", std::strerror(errno)));
  }
  absl::StatusOr<TempDir> dir = TempDir::Create("surfmap-itest");
  if (!dir.ok()) return dir.status();
  std::unique_ptr<ServerProcess> server(new ServerProcess(std::move(options), std::move(*dir)));
  if (!server->options_.config_json.empty()) {
    std::ofstream config(server->dir_.File("config.json"));
    config << server->options_.config_json;
    if (!config.good()) return absl::InternalError("cannot write " + server->dir_.File("config.json"));
  }
  if (absl::Status s = server->Launch(); !s.ok()) return s;
  return server;
}

ServerProcess::ServerProcess(ServerOptions options, TempDir dir)
    : options_(std::move(options)), dir_(std::move(dir)) {}

ServerProcess::~ServerProcess() {
  if (pid_ > 0) Kill().IgnoreError();
}

std::string ServerProcess::address() const { return absl::StrCat("127.0.0.1:", port_); }

std::shared_ptr<grpc::Channel> ServerProcess::NewChannel() const { return ConnectedChannel(address(), true); }

std::string ServerProcess::Log() const {
  std::string all;
  for (int i = 1; i <= launches_; ++i) {
    if (launches_ > 1) absl::StrAppend(&all, "----- launch ", i, " -----\n");
    absl::StrAppend(&all, ReadWholeFile(dir_.File(absl::StrCat("server-", i, ".log"))));
  }
  return all;
}

std::string ServerProcess::LogTail(size_t max_bytes) const {
  std::string log = Log();
  if (log.size() <= max_bytes) return log;
  return "[...]\n" + log.substr(log.size() - max_bytes);
}

absl::Status ServerProcess::Restart() {
  if (pid_ > 0) return absl::FailedPreconditionError("Restart: the server is still running");
  return Launch();
}

absl::Status ServerProcess::Launch() {
  ++launches_;
  const std::string port_file = dir_.File("port");
  const std::string log_file = dir_.File(absl::StrCat("server-", launches_, ".log"));
  std::remove(port_file.c_str());

  const int listen_port = options_.same_port_on_restart ? last_port_ : 0;
  std::vector<std::string> args = {options_.binary, "--listen", absl::StrCat("127.0.0.1:", listen_port), "--port-file", port_file,
                                   "--db", db_path()};
  if (!options_.config_json.empty()) {
    args.push_back("--config");
    args.push_back(dir_.File("config.json"));
  }
  args.insert(args.end(), options_.extra_args.begin(), options_.extra_args.end());
  const std::string command_line = absl::StrJoin(args, " ");

  // Everything the child touches is prepared here: between fork and exec only
  // async-signal-safe calls are allowed (other threads may hold malloc locks).
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  const pid_t parent = getpid();
  int log_fd = open(log_file.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (log_fd < 0) return absl::InternalError(absl::StrCat("cannot create ", log_file, ": ", std::strerror(errno)));
  int null_fd = open("/dev/null", O_RDONLY | O_CLOEXEC);

  pid_t pid = fork();
  if (pid < 0) {
    close(log_fd);
    if (null_fd >= 0) close(null_fd);
    return absl::InternalError(absl::StrCat("fork: ", std::strerror(errno)));
  }
  if (pid == 0) {
    prctl(PR_SET_PDEATHSIG, SIGKILL);
    if (getppid() != parent) _exit(127);  // the parent died before prctl
    if (null_fd >= 0) dup2(null_fd, STDIN_FILENO);
    dup2(log_fd, STDOUT_FILENO);
    dup2(log_fd, STDERR_FILENO);
    execv(argv[0], argv.data());
    const char message[] = "ServerProcess: execv failed\n";
    (void)!write(STDERR_FILENO, message, sizeof(message) - 1);
    _exit(127);
  }
  close(log_fd);
  if (null_fd >= 0) close(null_fd);
  pid_ = pid;
  port_ = 0;

  const Clock::time_point deadline = Clock::now() + options_.start_timeout;
  while (true) {
    int status = 0;
    if (waitpid(pid_, &status, WNOHANG) == pid_) {
      pid_ = -1;
      return absl::FailedPreconditionError(absl::StrCat(
          "surfmapd exited during startup (", WIFEXITED(status) ? absl::StrCat("exit code ", WEXITSTATUS(status))
                                                               : absl::StrCat("signal ", WTERMSIG(status)),
          ")\ncommand: ", command_line, "\nlog:\n", LogTail()));
    }
    int port = 0;
    if (ParsePortFile(ReadWholeFile(port_file), &port)) {
      port_ = port;
      last_port_ = port;
      break;
    }
    if (Clock::now() > deadline) {
      Kill().IgnoreError();
      return absl::DeadlineExceededError(absl::StrCat(
          "surfmapd did not write its port file ", port_file, " within ",
          options_.start_timeout.count(), " ms\ncommand: ", command_line, "\nlog:\n", LogTail()));
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }

  channel_ = MakeChannel(address());
  auto connect_deadline = std::chrono::system_clock::now() + std::chrono::seconds(20);
  if (!channel_->WaitForConnected(connect_deadline)) {
    return absl::UnavailableError(absl::StrCat("surfmapd wrote port ", port_, " but no connection within 20 s\n",
                                               "command: ", command_line, "\nlog:\n", LogTail()));
  }
  return absl::OkStatus();
}

void ServerProcess::Reap(int status, Clock::time_point since, ServerExit* exit) {
  exit->exited = WIFEXITED(status);
  exit->code = exit->exited ? WEXITSTATUS(status) : -1;
  exit->signal = WIFSIGNALED(status) ? WTERMSIG(status) : 0;
  exit->seconds = std::chrono::duration<double>(Clock::now() - since).count();
  pid_ = -1;
  channel_.reset();
}

absl::Status ServerProcess::Kill() {
  if (pid_ <= 0) return absl::FailedPreconditionError("Kill: the server is not running");
  const Clock::time_point since = Clock::now();
  kill(pid_, SIGKILL);
  int status = 0;
  while (waitpid(pid_, &status, 0) < 0 && errno == EINTR) {
  }
  ServerExit exit;
  Reap(status, since, &exit);
  return absl::OkStatus();
}

absl::Status ServerProcess::Signal(int signal) {
  if (pid_ <= 0) return absl::FailedPreconditionError("Signal: the server is not running");
  signalled_at_ = Clock::now();
  if (kill(pid_, signal) != 0) return absl::InternalError(absl::StrCat("kill: ", std::strerror(errno)));
  return absl::OkStatus();
}

absl::StatusOr<ServerExit> ServerProcess::WaitForExit(std::chrono::milliseconds timeout) {
  if (pid_ <= 0) return absl::FailedPreconditionError("WaitForExit: the server is not running");
  const Clock::time_point deadline = Clock::now() + timeout;
  while (true) {
    int status = 0;
    pid_t done = waitpid(pid_, &status, WNOHANG);
    if (done == pid_) {
      ServerExit exit;
      Reap(status, signalled_at_, &exit);
      return exit;
    }
    if (Clock::now() > deadline) {
      const double waited = std::chrono::duration<double>(Clock::now() - signalled_at_).count();
      Kill().IgnoreError();
      return absl::DeadlineExceededError(absl::StrCat("surfmapd still running ", waited,
                                                      " s after the signal; killed it. log:\n", LogTail()));
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
}

absl::StatusOr<ServerExit> ServerProcess::Stop(std::chrono::milliseconds timeout) {
  if (absl::Status s = Signal(SIGTERM); !s.ok()) return s;
  return WaitForExit(timeout);
}

}  // namespace surfmap::itest
