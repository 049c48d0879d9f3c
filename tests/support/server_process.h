// ServerProcess: the real surfmapd binary as a child process, for
// integration tests and the benchmark client.
//
// Start() makes a temp dir, launches `surfmapd --listen 127.0.0.1:0
// --port-file <dir>/port --db <dir>/surfmap.db [--config <dir>/config.json]`
// with stdout and stderr captured to <dir>/server-<n>.log, waits for the port
// file (written by the server once it accepts calls) and connects a channel.
// Kill() (SIGKILL) and Stop() (SIGTERM + wait) end it; Restart() launches it
// again on the same database (a new port, or the same one with
// `same_port_on_restart`, so clients that hold the address reconnect). The destructor SIGKILLs a server
// still running and removes the temp dir.
//
// The child is started with PR_SET_PDEATHSIG = SIGKILL, so a crashed test
// never leaves a server behind. That signal follows the THREAD that forked:
// call Start()/Restart() from a thread that outlives the server (the test's
// main thread), not from a short-lived worker.
#pragma once

#include <sys/types.h>

#include <chrono>
#include <memory>
#include <string>
#include <vector>

#include <grpcpp/channel.h>
#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "tests/support/temp_dir.h"

namespace surfmap::itest {

// The surfmapd this build made (compile definition SURFMAPD_PATH), or
// $SURFMAPD when set (to test an installed binary).
std::string DefaultSurfmapdPath();

struct ServerOptions {
  std::string binary = DefaultSurfmapdPath();
  std::string config_json;                 // non-empty: written to config.json, passed as --config
  std::vector<std::string> extra_args;     // appended after the standard flags
  // Restart() listens on the port of the previous launch (clients such as a
  // surfmap-rig process keep their address across the restart).
  bool same_port_on_restart = false;
  std::chrono::milliseconds start_timeout{60'000};  // generous: CI machines run tests in parallel
};

// How a stopped server ended.
struct ServerExit {
  bool exited = false;     // true: exit(code); false: killed by `signal`
  int code = -1;
  int signal = 0;
  double seconds = 0.0;    // from the signal sent to the process being reaped
};

class ServerProcess {
 public:
  // FAILED_PRECONDITION / DEADLINE_EXCEEDED / INTERNAL with the command line
  // and the server's log in the message when it does not come up.
  static absl::StatusOr<std::unique_ptr<ServerProcess>> Start(ServerOptions options = {});

  ~ServerProcess();
  ServerProcess(const ServerProcess&) = delete;
  ServerProcess& operator=(const ServerProcess&) = delete;

  // Launches the server again on the same database (it must not be running).
  absl::Status Restart();

  // SIGKILL and reap: the crash case (nothing flushed, no shutdown code runs).
  absl::Status Kill();

  // SIGTERM, then waits up to `timeout` for the process to exit. When it does
  // not, it is SIGKILLed and DEADLINE_EXCEEDED comes back (with the log).
  absl::StatusOr<ServerExit> Stop(std::chrono::milliseconds timeout);

  // Sends `signal` without waiting (for tests that watch the exit themselves).
  absl::Status Signal(int signal);
  // Waits up to `timeout` for the process to exit after a Signal().
  absl::StatusOr<ServerExit> WaitForExit(std::chrono::milliseconds timeout);

  bool running() const { return pid_ > 0; }
  int port() const { return port_; }
  std::string address() const;              // "127.0.0.1:<port>"
  const std::shared_ptr<grpc::Channel>& channel() const { return channel_; }
  // A separate, connected connection (its own subchannel), e.g. one per
  // simulated rig (see ConnectedChannel).
  std::shared_ptr<grpc::Channel> NewChannel() const;

  std::string db_path() const { return dir_.File("surfmap.db"); }
  std::string dir() const { return dir_.path().string(); }
  // Everything the server wrote to stdout/stderr, every launch, in order.
  std::string Log() const;
  // The last `max_bytes` of Log(), for failure messages.
  std::string LogTail(size_t max_bytes = 6000) const;

 private:
  ServerProcess(ServerOptions options, TempDir dir);
  absl::Status Launch();
  void Reap(int status, std::chrono::steady_clock::time_point since, ServerExit* exit);

  ServerOptions options_;
  TempDir dir_;
  pid_t pid_ = -1;
  int launches_ = 0;
  int port_ = 0;
  int last_port_ = 0;  // of the latest launch, kept after it ends
  std::shared_ptr<grpc::Channel> channel_;
  std::chrono::steady_clock::time_point signalled_at_{};
};

// A channel to `address` that accepts large responses (maps with meshes) and
// sends any size (so the server, not the client, enforces its limit).
// `own_subchannel`: do not share a TCP connection with other channels.
std::shared_ptr<grpc::Channel> MakeChannel(const std::string& address, bool own_subchannel = false);

// MakeChannel, then waits (up to 20 s) until it is connected. Tests that open
// many connections at once use this: gRPC 1.51 sometimes reports a fresh
// connect as failed with a stale errno ("No such file or directory",
// grpc/grpc#35064) and fails the first call UNAVAILABLE; waiting lets its own
// reconnect go through. Later calls still fail fast (a killed server shows).
std::shared_ptr<grpc::Channel> ConnectedChannel(const std::string& address, bool own_subchannel = false);

}  // namespace surfmap::itest
