#include "clients/remote/remote_call.h"

#include <algorithm>
#include <chrono>
#include <fstream>
#include <sstream>


namespace surfmap::cli {

std::shared_ptr<grpc::Channel> MakeChannel(const RemoteOptions& options, bool own_subchannel) {
  grpc::ChannelArguments args;
  args.SetMaxReceiveMessageSize(256 * 1024 * 1024);
  args.SetMaxSendMessageSize(256 * 1024 * 1024);
  args.SetInt(GRPC_ARG_KEEPALIVE_TIME_MS, 30'000);
  args.SetInt(GRPC_ARG_KEEPALIVE_TIMEOUT_MS, 10'000);
  args.SetInt(GRPC_ARG_KEEPALIVE_PERMIT_WITHOUT_CALLS, 0);
  if (own_subchannel) args.SetInt(GRPC_ARG_USE_LOCAL_SUBCHANNEL_POOL, 1);
  if (options.ca_file.empty()) return grpc::CreateCustomChannel(options.server, grpc::InsecureChannelCredentials(), args);
  // Read at every new channel (the rig makes one after each outage), so a
  // renewed CA file is picked up. An unreadable file gives empty roots and
  // every call fails its TLS handshake with the reason; the mains check the
  // file exists first.
  std::ifstream in(options.ca_file, std::ios::binary);
  std::stringstream pem;
  pem << in.rdbuf();
  grpc::SslCredentialsOptions tls;
  tls.pem_root_certs = pem.str();
  return grpc::CreateCustomChannel(options.server, grpc::SslCredentials(tls), args);
}

std::shared_ptr<grpc::Channel> ConnectChannel(const RemoteOptions& options) {
  std::shared_ptr<grpc::Channel> channel = MakeChannel(options);
  const double wait_s = options.timeout_s > 0 ? std::min(options.timeout_s, kConnectWaitS) : kConnectWaitS;
  // The result is not needed: a channel that did not connect makes the first
  // call fail with the real reason.
  channel->WaitForConnected(std::chrono::system_clock::now() +
                            std::chrono::microseconds(static_cast<long long>(wait_s * 1e6)));
  return channel;
}

void PrepareContext(const RemoteOptions& options, grpc::ClientContext* context, bool with_deadline) {
  if (with_deadline && options.timeout_s > 0) {
    context->set_deadline(std::chrono::system_clock::now() +
                          std::chrono::microseconds(static_cast<long long>(options.timeout_s * 1e6)));
  }
  if (!options.token.empty()) context->AddMetadata("authorization", "Bearer " + options.token);
}

std::string_view StatusCodeName(grpc::StatusCode code) {
  switch (code) {
    case grpc::StatusCode::OK: return "OK";
    case grpc::StatusCode::CANCELLED: return "CANCELLED";
    case grpc::StatusCode::UNKNOWN: return "UNKNOWN";
    case grpc::StatusCode::INVALID_ARGUMENT: return "INVALID_ARGUMENT";
    case grpc::StatusCode::DEADLINE_EXCEEDED: return "DEADLINE_EXCEEDED";
    case grpc::StatusCode::NOT_FOUND: return "NOT_FOUND";
    case grpc::StatusCode::ALREADY_EXISTS: return "ALREADY_EXISTS";
    case grpc::StatusCode::PERMISSION_DENIED: return "PERMISSION_DENIED";
    case grpc::StatusCode::RESOURCE_EXHAUSTED: return "RESOURCE_EXHAUSTED";
    case grpc::StatusCode::FAILED_PRECONDITION: return "FAILED_PRECONDITION";
    case grpc::StatusCode::ABORTED: return "ABORTED";
    case grpc::StatusCode::OUT_OF_RANGE: return "OUT_OF_RANGE";
    case grpc::StatusCode::UNIMPLEMENTED: return "UNIMPLEMENTED";
    case grpc::StatusCode::INTERNAL: return "INTERNAL";
    case grpc::StatusCode::UNAVAILABLE: return "UNAVAILABLE";
    case grpc::StatusCode::DATA_LOSS: return "DATA_LOSS";
    case grpc::StatusCode::UNAUTHENTICATED: return "UNAUTHENTICATED";
    default: return "UNKNOWN_CODE";
  }
}

std::string FormatRpcError(std::string_view rpc, const grpc::Status& status, std::string_view program) {
  std::string line(program);
  line.append(": ").append(rpc).append(": ").append(StatusCodeName(status.error_code()));
  line.append(": ").append(status.error_message());
  return line;
}

bool IsRetryable(grpc::StatusCode code) {
  return code == grpc::StatusCode::UNAVAILABLE || code == grpc::StatusCode::DEADLINE_EXCEEDED;
}

}  // namespace surfmap::cli
