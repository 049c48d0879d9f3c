// Glue for the CLI's remote commands: the global options (--server, --token,
// --timeout) and the one way every command makes a unary call, so every gRPC
// error is reported the same way (`surfmap: <RPC>: <CODE>: <message>` on
// stderr, exit code 1).
#pragma once

#include <iostream>
#include <memory>
#include <string>
#include <string_view>

#include <CLI/CLI.hpp>
#include <google/protobuf/message.h>
#include <grpcpp/grpcpp.h>
#include "clients/remote/remote_call.h"

namespace surfmap::cli {

// Exit codes of the CLI.
inline constexpr int kExitOk = 0;
inline constexpr int kExitRpcError = 1;   // the server answered with an error (or was unreachable)
inline constexpr int kExitUsage = 2;      // bad arguments, unreadable input, unwritable output

// What the remote commands share: the options (filled in by CLI11 before any
// callback runs) and the exit code they set.
struct RemoteCli {
  RemoteOptions options;
  int* exit_code = nullptr;

  // The channel, connected before its first use (see ConnectChannel).
  std::shared_ptr<grpc::Channel> Channel() {
    if (!channel_) channel_ = ConnectChannel(options);
    return channel_;
  }

 private:
  std::shared_ptr<grpc::Channel> channel_;
};

// Adds --server (env SURFMAP_SERVER), --token (env SURFMAP_TOKEN) and
// --timeout to `app`; subcommands see them before or after their own name.
std::shared_ptr<RemoteCli> AddRemoteOptions(CLI::App& app, int* exit_code);

// Calls stub.*method(request) with the deadline and token; on failure prints
// the error line and sets the exit code. Returns whether the call succeeded.
template <typename Stub, typename Request, typename Response>
bool CallRpc(RemoteCli& cli, std::string_view rpc_name, Stub& stub,
             grpc::Status (Stub::*method)(grpc::ClientContext*, const Request&, Response*), const Request& request,
             Response* response) {
  grpc::ClientContext context;
  PrepareContext(cli.options, &context);
  grpc::Status status = (stub.*method)(&context, request, response);
  if (status.ok()) return true;
  std::cout.flush();
  std::cerr << FormatRpcError(rpc_name, status) << "\n";
  *cli.exit_code = kExitRpcError;
  return false;
}

// Prints a usage/IO problem as `surfmap: <what>` and sets kExitUsage.
void FailUsage(RemoteCli& cli, std::string_view what);

// A message as protobuf JSON (snake_case field names, zero values printed).
std::string MessageToJson(const google::protobuf::Message& message, bool pretty = true);

}  // namespace surfmap::cli
