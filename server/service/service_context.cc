#include "server/service/service_context.h"

namespace surfmap {
namespace {

bool IsServerError(absl::StatusCode code) {
  return code == absl::StatusCode::kInternal || code == absl::StatusCode::kDataLoss ||
         code == absl::StatusCode::kUnknown || code == absl::StatusCode::kUnavailable;
}

}  // namespace

void FinishUnary(grpc::ServerUnaryReactor* reactor, const char* method, const absl::Status& status) {
  if (!status.ok()) {
    if (IsServerError(status.code())) {
      spdlog::warn("rpc={} code={} error=\"{}\"", method, absl::StatusCodeToString(status.code()), std::string(status.message()));
    } else {
      spdlog::debug("rpc={} code={} error=\"{}\"", method, absl::StatusCodeToString(status.code()), std::string(status.message()));
    }
  }
  reactor->Finish(ToGrpcStatus(status));
}

grpc::ServerUnaryReactor* HandleUnary(grpc::CallbackServerContext* context, const ServiceContext& services,
                                      Role needed, const char* method, const std::function<absl::Status()>& work) {
  grpc::ServerUnaryReactor* reactor = context->DefaultReactor();
  absl::Status admitted = services.gate->Admit(*context, needed, method);
  FinishUnary(reactor, method, admitted.ok() ? work() : admitted);
  return reactor;
}

grpc::ServerUnaryReactor* HandleUnaryOnPool(grpc::CallbackServerContext* context, const ServiceContext& services,
                                            Role needed, const char* method, std::function<absl::Status()> work) {
  grpc::ServerUnaryReactor* reactor = context->DefaultReactor();
  absl::Status admitted = services.gate->Admit(*context, needed, method);
  if (!admitted.ok()) {
    FinishUnary(reactor, method, admitted);
    return reactor;
  }
  bool queued = services.pool->Submit([reactor, method, work = std::move(work)] { FinishUnary(reactor, method, work()); });
  if (!queued) FinishUnary(reactor, method, absl::UnavailableError("server busy: work queue full, retry later"));
  return reactor;
}

}  // namespace surfmap
