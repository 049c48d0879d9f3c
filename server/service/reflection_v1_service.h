// gRPC server reflection, protocol v1 (grpc.reflection.v1.ServerReflection).
//
// Debian 12's libgrpc++_reflection (gRPC 1.51) serves only v1alpha; current
// grpcurl, Postman and grpc_cli ask for v1 first. The two protocols are the
// same messages under two package names, so this serves v1 from the same
// source v1alpha uses: the descriptors compiled into the binary
// (DescriptorPool::generated_pool()). v1alpha stays registered beside it
// (grpc::reflection::InitProtoReflectionServerBuilderPlugin) for older tools.
//
// Answers, per request of the bidirectional stream, as gRPC's own
// implementation does: list_services (the names given at construction),
// file_by_filename and file_containing_symbol / _extension (the file and
// every file it imports, each once per response), all_extension_numbers_of_type.
// Unknown names get an error_response NOT_FOUND, an empty request
// INVALID_ARGUMENT; the stream stays open either way.
#pragma once

#include <string>
#include <vector>

#include <grpcpp/grpcpp.h>
#include "grpc/reflection/v1/reflection.grpc.pb.h"

namespace surfmap {

// One answer to one request (no I/O): what the stream writes back.
grpc::reflection::v1::ServerReflectionResponse AnswerReflectionRequest(
    const grpc::reflection::v1::ServerReflectionRequest& request, const std::vector<std::string>& service_names);

class ReflectionV1Service final : public grpc::reflection::v1::ServerReflection::CallbackService {
 public:
  // `service_names`: the full names listed by list_services.
  explicit ReflectionV1Service(std::vector<std::string> service_names) : service_names_(std::move(service_names)) {}

  grpc::ServerBidiReactor<grpc::reflection::v1::ServerReflectionRequest,
                          grpc::reflection::v1::ServerReflectionResponse>*
  ServerReflectionInfo(grpc::CallbackServerContext* context) override;

 private:
  const std::vector<std::string> service_names_;
};

}  // namespace surfmap
