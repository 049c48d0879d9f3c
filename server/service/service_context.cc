#include "server/service/service_context.h"

#include <atomic>
#include <exception>
#include <memory>

#include <spdlog/spdlog.h>
#include "server/base/log_text.h"

namespace surfmap {
namespace {

bool IsServerError(absl::StatusCode code) {
  return code == absl::StatusCode::kInternal || code == absl::StatusCode::kDataLoss ||
         code == absl::StatusCode::kUnknown || code == absl::StatusCode::kUnavailable;
}

// Runs `work`, turning an escaped exception into INTERNAL with its message
// (a handler must answer, whatever went wrong below it).
absl::Status RunGuarded(const std::function<absl::Status()>& work, const char* method) {
  try {
    return work();
  } catch (const std::exception& e) {
    return absl::InternalError(std::string(method) + " failed: " + e.what());
  } catch (...) {
    return absl::InternalError(std::string(method) + " failed with an unknown exception");
  }
}

}  // namespace

void FinishUnary(grpc::ServerUnaryReactor* reactor, const char* method, const absl::Status& status) {
  if (!status.ok()) {
    if (IsServerError(status.code())) {
      spdlog::warn("call failed rpc={} code={} error={}", method, absl::StatusCodeToString(status.code()),
                   LogQuote(std::string(status.message())));
    } else {
      spdlog::debug("call refused rpc={} code={} error={}", method, absl::StatusCodeToString(status.code()),
                    LogQuote(std::string(status.message())));
    }
  }
  reactor->Finish(ToGrpcStatus(status));
}

grpc::ServerUnaryReactor* HandleUnary(grpc::CallbackServerContext* context, const ServiceContext& services,
                                      Role needed, const char* method, const std::function<absl::Status()>& work) {
  grpc::ServerUnaryReactor* reactor = context->DefaultReactor();
  absl::Status admitted = AdmitCall(*context, services, needed, method);
  FinishUnary(reactor, method, admitted.ok() ? RunGuarded(work, method) : admitted);
  return reactor;
}

absl::Status AdmitCall(const grpc::ServerContextBase& context, const ServiceContext& services, Role needed,
                       const char* method) {
  absl::Status admitted = services.gate->Admit(context, needed, method);
  if (!admitted.ok()) {
    // The gate's messages name the method and the missing role, never the
    // token (a wrong token is "unknown token"), so the line is safe to keep.
    spdlog::warn("auth failure rpc={} peer={} code={} reason={}", method, LogQuote(context.peer()),
                 absl::StatusCodeToString(admitted.code()), LogQuote(std::string(admitted.message())));
  }
  return admitted;
}

grpc::ServerUnaryReactor* HandleUnaryOnPool(grpc::CallbackServerContext* context, const ServiceContext& services,
                                            Role needed, const char* method, std::function<absl::Status()> work) {
  grpc::ServerUnaryReactor* reactor = context->DefaultReactor();
  absl::Status admitted = AdmitCall(*context, services, needed, method);
  if (!admitted.ok()) {
    FinishUnary(reactor, method, admitted);
    return reactor;
  }
  bool queued = services.pool->Submit(
      [reactor, method, work = std::move(work)] { FinishUnary(reactor, method, RunGuarded(work, method)); });
  if (!queued) FinishUnary(reactor, method, absl::UnavailableError("server busy: work queue full, retry later"));
  return reactor;
}

grpc::ServerUnaryReactor* HandleUnaryInlineIf(bool cheap, grpc::CallbackServerContext* context,
                                              const ServiceContext& services, Role needed, const char* method,
                                              std::function<absl::Status()> work) {
  return cheap ? HandleUnary(context, services, needed, method, work)
               : HandleUnaryOnPool(context, services, needed, method, std::move(work));
}

grpc::ServerUnaryReactor* HandleUnaryAsync(grpc::CallbackServerContext* context, const ServiceContext& services,
                                           Role needed, const char* method,
                                           const std::function<void(FinishFn finish)>& start) {
  grpc::ServerUnaryReactor* reactor = context->DefaultReactor();
  absl::Status admitted = AdmitCall(*context, services, needed, method);
  if (!admitted.ok()) {
    FinishUnary(reactor, method, admitted);
    return reactor;
  }
  // `start` may throw after it handed `finish` on (or before): whichever of
  // the two comes first answers, once.
  auto answered = std::make_shared<std::atomic<bool>>(false);
  FinishFn finish = [reactor, method, answered](absl::Status status) {
    if (!answered->exchange(true)) FinishUnary(reactor, method, status);
  };
  absl::Status thrown = RunGuarded(
      [&]() -> absl::Status {
        start(finish);
        return absl::OkStatus();
      },
      method);
  if (!thrown.ok()) finish(thrown);
  return reactor;
}

}  // namespace surfmap
