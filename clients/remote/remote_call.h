// What every remote command of the surfmap clients shares: the channel to
// surfmapd, the per-call deadline and bearer token, and the one error line
// format (`surfmap: <RPC>: <CODE>: <message>`).
#pragma once

#include <memory>
#include <string>
#include <string_view>

#include <grpcpp/grpcpp.h>

namespace surfmap::cli {

struct RemoteOptions {
  std::string server = "127.0.0.1:50051";  // host:port of surfmapd
  std::string token;                       // sent as `authorization: Bearer <token>` when not empty
  double timeout_s = 30.0;                 // deadline of every unary call; <= 0 = none
  // PEM file of the CA that signed the server's certificate: when set, the
  // channel is TLS and verifies the server against this CA only.
  std::string ca_file;
};

// The address used when neither --server nor $SURFMAP_SERVER is given.
inline constexpr std::string_view kDefaultServer = "127.0.0.1:50051";

// A TLS channel when `options.ca_file` is set, else a plaintext one (a
// surfmapd on loopback), that accepts messages up to 256 MiB (maps with meshes are large; the
// server's own limit is lower) and sends keepalive pings so a long watch
// notices a vanished server. `own_subchannel`: a connection of its own, not
// shared with (nor inheriting the reconnect backoff of) other channels to the
// same address.
std::shared_ptr<grpc::Channel> MakeChannel(const RemoteOptions& options, bool own_subchannel = false);

// MakeChannel, then waits up to kConnectWait (or the timeout, if shorter) for
// the connection. Why: gRPC 1.51 (Debian 12) can report a fresh TCP connect as
// failed with a stale errno ("UNKNOWN: ...: No such file or directory",
// grpc/grpc#35064), and a call made in that moment fails UNAVAILABLE although
// the server is up; the wait lets gRPC's own reconnect (about 1 s later) go
// through. A server that is really down still gives the usual UNAVAILABLE
// error, after the wait.
inline constexpr double kConnectWaitS = 2.5;
std::shared_ptr<grpc::Channel> ConnectChannel(const RemoteOptions& options);

// Sets the deadline (when timeout_s > 0 and `with_deadline`) and the
// authorization metadata on a fresh context. Streams that last as long as a
// job (WatchJob) pass with_deadline = false.
void PrepareContext(const RemoteOptions& options, grpc::ClientContext* context, bool with_deadline = true);

// "OK", "INVALID_ARGUMENT", ... (the canonical names).
std::string_view StatusCodeName(grpc::StatusCode code);

// "<program>: <rpc>: <CODE>: <message>" (no newline).
std::string FormatRpcError(std::string_view rpc, const grpc::Status& status, std::string_view program = "surfmap");

// Whether a call that failed with `code` may be retried as is (the server
// was unreachable or slow; the request itself was fine).
bool IsRetryable(grpc::StatusCode code);

}  // namespace surfmap::cli
