#include "server/service/status_interceptor.h"

#include <spdlog/spdlog.h>
#include "absl/strings/str_cat.h"

namespace surfmap {
namespace {

class StatusInterceptor final : public grpc::experimental::Interceptor {
 public:
  StatusInterceptor(const char* method, bool known) : method_(method), known_(known) {}

  void Intercept(grpc::experimental::InterceptorBatchMethods* methods) override {
    using Hook = grpc::experimental::InterceptionHookPoints;
    // The server sets the received message to null when it did not parse.
    if (methods->QueryInterceptionHookPoint(Hook::POST_RECV_MESSAGE) && methods->GetRecvMessage() == nullptr) {
      unparsed_ = true;
    }
    if (methods->QueryInterceptionHookPoint(Hook::PRE_SEND_STATUS)) {
      const grpc::Status status = methods->GetSendStatus();
      if (status.error_code() == grpc::StatusCode::UNIMPLEMENTED && status.error_message().empty()) {
        methods->ModifySendStatus(Explain());
      }
    }
    methods->Proceed();
  }

 private:
  grpc::Status Explain() const {
    if (!known_) {
      return grpc::Status(grpc::StatusCode::UNIMPLEMENTED,
                          absl::StrCat("method ", method_, " does not exist on this server (surfmap.v1)"));
    }
    if (unparsed_) {
      spdlog::debug("rpc={} code=INVALID_ARGUMENT error=\"request did not parse\"", method_);
      return grpc::Status(grpc::StatusCode::INVALID_ARGUMENT,
                          absl::StrCat(method_, ": the request could not be parsed as its protobuf message "
                                                "(malformed bytes, or a string field that is not valid UTF-8)"));
    }
    spdlog::error("rpc={} code=INTERNAL error=\"the handler threw before answering\"", method_);
    return grpc::Status(grpc::StatusCode::INTERNAL,
                        absl::StrCat(method_, ": the server failed while handling the call (see its log)"));
  }

  const std::string method_;
  const bool known_;
  bool unparsed_ = false;  // one call's hooks run one at a time
};

class StatusInterceptorFactory final : public grpc::experimental::ServerInterceptorFactoryInterface {
 public:
  explicit StatusInterceptorFactory(std::set<std::string> methods) : methods_(std::move(methods)) {}
  grpc::experimental::Interceptor* CreateServerInterceptor(grpc::experimental::ServerRpcInfo* info) override {
    const char* method = info->method() != nullptr ? info->method() : "";
    return new StatusInterceptor(method, methods_.count(method) > 0);
  }

 private:
  const std::set<std::string> methods_;
};

}  // namespace

std::unique_ptr<grpc::experimental::ServerInterceptorFactoryInterface> MakeStatusInterceptorFactory(
    std::set<std::string> methods) {
  return std::make_unique<StatusInterceptorFactory>(std::move(methods));
}

}  // namespace surfmap
