#include "absl/strings/str_cat.h"
#include "server/service/grpc_services.h"
#include "server/service/proto_builders.h"

namespace surfmap {

grpc::ServerUnaryReactor* ObjectServiceImpl::UploadObject(grpc::CallbackServerContext* context,
                                                          const pb::UploadObjectRequest* request,
                                                          pb::UploadObjectResponse* response) {
  // Parsing and refining a mesh can take a while: off the gRPC threads.
  return HandleUnaryOnPool(context, s_, Role::kSteer, "UploadObject", [this, request, response]() -> absl::Status {
    MeshFormat format;
    switch (request->format()) {
      case pb::MESH_FORMAT_OBJ: format = MeshFormat::kObj; break;
      case pb::MESH_FORMAT_PLY: format = MeshFormat::kPly; break;
      case pb::MESH_FORMAT_UNSPECIFIED: return absl::InvalidArgumentError("format must be OBJ or PLY (UNSPECIFIED is rejected)");
      default: return absl::InvalidArgumentError(absl::StrCat("format: unknown value ", request->format()));
    }
    absl::StatusOr<ObjectRecord> object = s_.coordinator->UploadObject(request->name(), format, request->mesh());
    if (!object.ok()) return object.status();
    *response->mutable_object() = ObjectInfoToProto(*object);
    spdlog::info("rpc=UploadObject object_id={} name=\"{}\" vertices={} faces={}", object->id, object->name,
                 object->control_vertices, object->control_faces);
    return absl::OkStatus();
  });
}

grpc::ServerUnaryReactor* ObjectServiceImpl::GetObject(grpc::CallbackServerContext* context,
                                                       const pb::GetObjectRequest* request,
                                                       pb::GetObjectResponse* response) {
  return HandleUnary(context, s_, Role::kRead, "GetObject", [&]() -> absl::Status {
    absl::StatusOr<ObjectRecord> object = s_.coordinator->reads().GetObject(request->object_id());
    if (!object.ok()) return object.status();
    *response->mutable_object() = ObjectInfoToProto(*object);
    return absl::OkStatus();
  });
}

grpc::ServerUnaryReactor* ObjectServiceImpl::ListObjects(grpc::CallbackServerContext* context,
                                                         const pb::ListObjectsRequest*,
                                                         pb::ListObjectsResponse* response) {
  return HandleUnary(context, s_, Role::kRead, "ListObjects", [&]() -> absl::Status {
    absl::StatusOr<std::vector<ObjectRecord>> objects = s_.coordinator->reads().ListObjects();
    if (!objects.ok()) return objects.status();
    for (const ObjectRecord& o : *objects) *response->add_objects() = ObjectInfoToProto(o);
    return absl::OkStatus();
  });
}

grpc::ServerUnaryReactor* ObjectServiceImpl::GetMesh(grpc::CallbackServerContext* context,
                                                     const pb::GetMeshRequest* request,
                                                     pb::GetMeshResponse* response) {
  return HandleUnaryOnPool(context, s_, Role::kRead, "GetMesh", [this, request, response]() -> absl::Status {
    absl::StatusOr<std::shared_ptr<const LoopSurface>> surface =
        s_.coordinator->Surface(request->object_id(), request->level());
    if (!surface.ok()) return surface.status();
    FillMesh((*surface)->level(request->level()), request->level(), request->object_id(), response);
    return absl::OkStatus();
  });
}

}  // namespace surfmap
