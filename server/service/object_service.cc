#include "absl/strings/str_cat.h"
#include "server/base/utf8_text.h"
#include "server/service/provenance_proto.h"
#include "server/service/grpc_services.h"
#include "server/service/proto_builders.h"
#include "server/mesh/mesh_units.h"

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
      case pb::MESH_FORMAT_STL: format = MeshFormat::kStl; break;
      case pb::MESH_FORMAT_UNSPECIFIED:
        return absl::InvalidArgumentError("format must be OBJ, PLY or STL (UNSPECIFIED is rejected)");
      default: return absl::InvalidArgumentError(absl::StrCat("format: unknown value ", request->format()));
    }
    if (absl::Status s = ValidateName("name", request->name(), 1, 200); !s.ok()) return s;
    absl::StatusOr<Provenance> provenance = ProvenanceFromProto(request->provenance());
    if (!provenance.ok()) return provenance.status();
    JobCoordinator::UploadOptions options;
    if (request->has_scale()) {
      options.mm_per_unit = request->scale();
      options.unit_text = absl::StrCat("scale ", request->scale(), " mm per unit");
      options.unit_stated = true;
    } else if (request->units() != pb::LENGTH_UNIT_UNSPECIFIED) {
      LengthUnit unit;
      switch (request->units()) {
        case pb::LENGTH_UNIT_MM: unit = LengthUnit::kMm; break;
        case pb::LENGTH_UNIT_CM: unit = LengthUnit::kCm; break;
        case pb::LENGTH_UNIT_M: unit = LengthUnit::kM; break;
        case pb::LENGTH_UNIT_IN: unit = LengthUnit::kIn; break;
        default: return absl::InvalidArgumentError(absl::StrCat("units: unknown value ", request->units()));
      }
      options.mm_per_unit = MmPerUnit(unit);
      options.unit_text = LengthUnitName(unit);
      options.unit_stated = true;
    }
    switch (request->surface()) {
      case pb::OBJECT_SURFACE_UNSPECIFIED:
      case pb::OBJECT_SURFACE_CONTROL_MESH: options.facets = false; break;
      case pb::OBJECT_SURFACE_FACETS: options.facets = true; break;
      default: return absl::InvalidArgumentError(absl::StrCat("surface: unknown value ", request->surface()));
    }
    absl::StatusOr<UploadedObject> uploaded =
        s_.coordinator->UploadObject(request->name(), format, request->mesh(), options, *provenance);
    if (!uploaded.ok()) return uploaded.status();
    const ObjectRecord& object = uploaded->object;
    *response->mutable_object() = ObjectInfoToProto(object);
    for (const MeshRepairNote& r : uploaded->repairs) {
      pb::MeshRepair* repair = response->add_repairs();
      repair->set_kind(r.kind);
      repair->set_count(r.count);
      repair->set_detail(r.detail);
    }
    for (const std::string& w : uploaded->warnings) response->add_warnings(w);
    response->set_scale_mm(uploaded->mm_per_unit);
    response->mutable_extent_mm()->set_x(uploaded->extent_mm.x());
    response->mutable_extent_mm()->set_y(uploaded->extent_mm.y());
    response->mutable_extent_mm()->set_z(uploaded->extent_mm.z());
    response->set_area_mm2(uploaded->area_mm2);
    spdlog::info(
        "rpc=UploadObject object_id={} name=\"{}\" vertices={} faces={} surface={} scale={} repairs={} warnings={}",
        object.id, object.name, object.control_vertices, object.control_faces, object.surface, uploaded->mm_per_unit,
        uploaded->repairs.size(), uploaded->warnings.size());
    return absl::OkStatus();
  });
}

grpc::ServerUnaryReactor* ObjectServiceImpl::GetObject(grpc::CallbackServerContext* context,
                                                       const pb::GetObjectRequest* request,
                                                       pb::GetObjectResponse* response) {
  return HandleUnaryOnPool(context, s_, Role::kRead, "GetObject", [this, request, response]() -> absl::Status {
    absl::StatusOr<ObjectRecord> object = s_.coordinator->reads().GetObject(request->object_id());
    if (!object.ok()) return object.status();
    *response->mutable_object() = ObjectInfoToProto(*object);
    return absl::OkStatus();
  });
}

grpc::ServerUnaryReactor* ObjectServiceImpl::ListObjects(grpc::CallbackServerContext* context,
                                                         const pb::ListObjectsRequest*,
                                                         pb::ListObjectsResponse* response) {
  return HandleUnaryOnPool(context, s_, Role::kRead, "ListObjects", [this, response]() -> absl::Status {
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
