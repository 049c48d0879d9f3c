#include "server/service/reflection_v1_service.h"

#include <set>
#include <utility>

#include <google/protobuf/descriptor.h>
#include <google/protobuf/descriptor.pb.h>

namespace surfmap {
namespace {

namespace rv1 = ::grpc::reflection::v1;
using google::protobuf::DescriptorPool;
using google::protobuf::FileDescriptor;

// The file, then what it imports (depth first), each file once: a client
// needs every import to build the file's descriptors.
void AddFileAndImports(const FileDescriptor& file, std::set<std::string>& sent, rv1::FileDescriptorResponse& out) {
  if (!sent.insert(file.name()).second) return;
  google::protobuf::FileDescriptorProto proto;
  file.CopyTo(&proto);
  out.add_file_descriptor_proto(proto.SerializeAsString());
  for (int i = 0; i < file.dependency_count(); ++i) AddFileAndImports(*file.dependency(i), sent, out);
}

void SetError(rv1::ServerReflectionResponse& response, grpc::StatusCode code, const std::string& message) {
  response.mutable_error_response()->set_error_code(static_cast<int32_t>(code));
  response.mutable_error_response()->set_error_message(message);
}

void SetFile(rv1::ServerReflectionResponse& response, const FileDescriptor* file, const std::string& what) {
  if (file == nullptr) return SetError(response, grpc::StatusCode::NOT_FOUND, what + " not found");
  std::set<std::string> sent;
  AddFileAndImports(*file, sent, *response.mutable_file_descriptor_response());
}

// Reads requests one at a time and writes one answer each; the next read
// starts when the write is done, so a slow client holds one response.
class ReflectionStream final
    : public grpc::ServerBidiReactor<rv1::ServerReflectionRequest, rv1::ServerReflectionResponse> {
 public:
  explicit ReflectionStream(const std::vector<std::string>& service_names) : service_names_(service_names) {
    StartRead(&request_);
  }

  void OnReadDone(bool ok) override {
    if (!ok) return Finish(grpc::Status::OK);  // the client is done writing
    response_ = AnswerReflectionRequest(request_, service_names_);
    StartWrite(&response_);
  }

  void OnWriteDone(bool ok) override {
    if (!ok) return Finish(grpc::Status(grpc::StatusCode::CANCELLED, "reflection response not delivered"));
    StartRead(&request_);
  }

  void OnDone() override { delete this; }

 private:
  const std::vector<std::string>& service_names_;
  rv1::ServerReflectionRequest request_;
  rv1::ServerReflectionResponse response_;
};

}  // namespace

rv1::ServerReflectionResponse AnswerReflectionRequest(const rv1::ServerReflectionRequest& request,
                                                      const std::vector<std::string>& service_names) {
  const DescriptorPool& pool = *DescriptorPool::generated_pool();
  rv1::ServerReflectionResponse response;
  response.set_valid_host(request.host());
  *response.mutable_original_request() = request;
  switch (request.message_request_case()) {
    case rv1::ServerReflectionRequest::kListServices:
      for (const std::string& name : service_names) {
        response.mutable_list_services_response()->add_service()->set_name(name);
      }
      break;
    case rv1::ServerReflectionRequest::kFileByFilename:
      SetFile(response, pool.FindFileByName(request.file_by_filename()), "file " + request.file_by_filename());
      break;
    case rv1::ServerReflectionRequest::kFileContainingSymbol:
      SetFile(response, pool.FindFileContainingSymbol(request.file_containing_symbol()),
              "symbol " + request.file_containing_symbol());
      break;
    case rv1::ServerReflectionRequest::kFileContainingExtension: {
      const rv1::ExtensionRequest& e = request.file_containing_extension();
      const google::protobuf::Descriptor* type = pool.FindMessageTypeByName(e.containing_type());
      const google::protobuf::FieldDescriptor* extension =
          type == nullptr ? nullptr : pool.FindExtensionByNumber(type, e.extension_number());
      SetFile(response, extension == nullptr ? nullptr : extension->file(),
              "extension " + std::to_string(e.extension_number()) + " of " + e.containing_type());
      break;
    }
    case rv1::ServerReflectionRequest::kAllExtensionNumbersOfType: {
      const google::protobuf::Descriptor* type = pool.FindMessageTypeByName(request.all_extension_numbers_of_type());
      if (type == nullptr) {
        SetError(response, grpc::StatusCode::NOT_FOUND, "type " + request.all_extension_numbers_of_type() + " not found");
        break;
      }
      std::vector<const google::protobuf::FieldDescriptor*> extensions;
      pool.FindAllExtensions(type, &extensions);
      rv1::ExtensionNumberResponse* numbers = response.mutable_all_extension_numbers_response();
      numbers->set_base_type_name(type->full_name());
      for (const auto* extension : extensions) numbers->add_extension_number(extension->number());
      break;
    }
    case rv1::ServerReflectionRequest::MESSAGE_REQUEST_NOT_SET:
      SetError(response, grpc::StatusCode::INVALID_ARGUMENT, "empty reflection request");
      break;
  }
  return response;
}

grpc::ServerBidiReactor<rv1::ServerReflectionRequest, rv1::ServerReflectionResponse>*
ReflectionV1Service::ServerReflectionInfo(grpc::CallbackServerContext* /*context*/) {
  return new ReflectionStream(service_names_);
}

}  // namespace surfmap
