// The status interceptor and HandleUnaryAsync's guard, on a real in-process
// gRPC server (127.0.0.1, free port) with a service whose handlers throw:
// what gRPC 1.51 would answer as UNIMPLEMENTED "" comes back with a code and
// a message.
#include "server/service/status_interceptor.h"

#include <stdexcept>

#include <grpcpp/generic/generic_stub.h>
#include <grpcpp/grpcpp.h>
#include "gtest/gtest.h"
#include "proto/surfmap/v1/surfmap.grpc.pb.h"
#include "server/service/service_context.h"

namespace surfmap {
namespace {

namespace pb = ::surfmap::v1;

// GetObject throws before it returns a reactor (gRPC catches that and, by
// itself, answers UNIMPLEMENTED ""); ListObjects throws inside the start of
// an asynchronous handler (HandleUnaryAsync must answer INTERNAL, once).
class ThrowingObjects final : public pb::ObjectService::CallbackService {
 public:
  explicit ThrowingObjects(ServiceContext services) : s_(services) {}
  grpc::ServerUnaryReactor* GetObject(grpc::CallbackServerContext*, const pb::GetObjectRequest*,
                                      pb::GetObjectResponse*) override {
    throw std::runtime_error("boom before the reactor");
  }
  grpc::ServerUnaryReactor* ListObjects(grpc::CallbackServerContext* context, const pb::ListObjectsRequest*,
                                        pb::ListObjectsResponse*) override {
    return HandleUnaryAsync(context, s_, Role::kRead, "ListObjects",
                            [](FinishFn) { throw std::runtime_error("boom in start"); });
  }

 private:
  ServiceContext s_;
};

class StatusInterceptorTest : public ::testing::Test {
 protected:
  void SetUp() override {
    grpc::ServerBuilder builder;
    builder.AddListeningPort("127.0.0.1:0", grpc::InsecureServerCredentials(), &port_);
    builder.RegisterService(&service_);
    std::vector<std::unique_ptr<grpc::experimental::ServerInterceptorFactoryInterface>> interceptors;
    interceptors.push_back(MakeStatusInterceptorFactory(
        {"/surfmap.v1.ObjectService/GetObject", "/surfmap.v1.ObjectService/ListObjects"}));
    builder.experimental().SetInterceptorCreators(std::move(interceptors));
    server_ = builder.BuildAndStart();
    ASSERT_TRUE(server_ != nullptr);
    channel_ = grpc::CreateChannel("127.0.0.1:" + std::to_string(port_), grpc::InsecureChannelCredentials());
    stub_ = pb::ObjectService::NewStub(channel_);
  }
  void TearDown() override { server_->Shutdown(); }

  std::unique_ptr<grpc::ClientContext> Context() {
    auto context = std::make_unique<grpc::ClientContext>();
    context->set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(10));
    return context;
  }

  static ServiceContext WithGate(const RequestGate* gate) {
    ServiceContext services;
    services.gate = gate;  // open access: the handlers are reached
    return services;
  }

  RequestGate gate_;
  ThrowingObjects service_{WithGate(&gate_)};
  int port_ = 0;
  std::unique_ptr<grpc::Server> server_;
  std::shared_ptr<grpc::Channel> channel_;
  std::unique_ptr<pb::ObjectService::Stub> stub_;
};

TEST_F(StatusInterceptorTest, AHandlerThatThrowsBeforeItsReactorIsInternalWithAMessage) {
  pb::GetObjectRequest request;
  request.set_object_id(1);
  pb::GetObjectResponse response;
  const grpc::Status status = stub_->GetObject(Context().get(), request, &response);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INTERNAL) << status.error_message();
  EXPECT_EQ(status.error_message(),
            "/surfmap.v1.ObjectService/GetObject: the server failed while handling the call (see its log)");
}

TEST_F(StatusInterceptorTest, AnAsyncStartThatThrowsIsAnsweredOnceAsInternal) {
  pb::ListObjectsResponse response;
  const grpc::Status status = stub_->ListObjects(Context().get(), pb::ListObjectsRequest(), &response);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INTERNAL);
  EXPECT_EQ(status.error_message(), "ListObjects failed: boom in start");
}

TEST_F(StatusInterceptorTest, ARequestThatDoesNotParseIsInvalidArgument) {
  grpc::GenericStub stub(channel_);
  const std::string bytes("\x0a\xff\xff\xff\xff\x0f", 6);  // field 1, a length that runs past the end
  grpc::Slice slice(bytes);
  grpc::ByteBuffer request(&slice, 1), response;
  auto context = Context();
  grpc::CompletionQueue queue;
  auto call = stub.PrepareUnaryCall(context.get(), "/surfmap.v1.ObjectService/GetObject", request, &queue);
  call->StartCall();
  grpc::Status status;
  call->Finish(&response, &status, reinterpret_cast<void*>(1));
  void* tag = nullptr;
  bool ok = false;
  ASSERT_TRUE(queue.Next(&tag, &ok));
  queue.Shutdown();
  while (queue.Next(&tag, &ok)) {
  }
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT) << status.error_message();
  EXPECT_NE(status.error_message().find("could not be parsed"), std::string::npos) << status.error_message();
}

}  // namespace
}  // namespace surfmap
