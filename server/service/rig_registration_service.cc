// ObjectService: the rigs' registrations to objects (frames and calibration).
#include <spdlog/spdlog.h>
#include "absl/strings/str_cat.h"
#include "server/service/grpc_services.h"
#include "server/service/rig_registration_proto.h"

namespace surfmap {

grpc::ServerUnaryReactor* ObjectServiceImpl::SetRigRegistration(grpc::CallbackServerContext* context,
                                                                const pb::SetRigRegistrationRequest* request,
                                                                pb::SetRigRegistrationResponse* response) {
  // A durable write: on the pool, never on a gRPC thread.
  return HandleUnaryOnPool(context, s_, Role::kSteer, "SetRigRegistration", [this, request, response]() -> absl::Status {
    const pb::RigRegistration& in = request->registration();
    if (in.object_id() <= 0) return absl::InvalidArgumentError("registration.object_id must be a positive object id");
    if (!in.has_object_pose() || !in.object_pose().has_rotation()) {
      return absl::InvalidArgumentError("registration.object_pose.rotation is required (a unit quaternion w, x, y, z)");
    }
    // Never a silent (0, 0, 0): the object at the rig's base origin would send
    // the robot there.
    if (!in.object_pose().has_translation_mm()) {
      return absl::InvalidArgumentError(
          "registration.object_pose.translation_mm is required (the object's origin in the rig's base frame, mm)");
    }
    absl::StatusOr<RigRegistration> registration = RigRegistrationFromProto(in);
    if (!registration.ok()) {
      return absl::Status(registration.status().code(),
                          absl::StrCat("registration: ", registration.status().message()));
    }
    absl::StatusOr<RegisteredRig> stored = s_.coordinator->rigs().Register(in.object_id(), in.rig_name(), *registration);
    if (!stored.ok()) return stored.status();
    *response->mutable_registration() = RegisteredRigToProto(*stored);
    spdlog::info("rpc=SetRigRegistration object_id={} rig=\"{}\" registration_id={} version={} tip_radius_mm={}",
                 stored->record.object_id, stored->record.rig_name, stored->record.id, stored->record.version,
                 stored->registration.tip_radius_mm);
    return absl::OkStatus();
  });
}

grpc::ServerUnaryReactor* ObjectServiceImpl::GetRigRegistration(grpc::CallbackServerContext* context,
                                                                const pb::GetRigRegistrationRequest* request,
                                                                pb::GetRigRegistrationResponse* response) {
  return HandleUnaryOnPool(context, s_, Role::kRead, "GetRigRegistration", [this, request, response]() -> absl::Status {
    RigRegistrations& rigs = s_.coordinator->rigs();
    if (request->registration_id() != 0) {
      absl::StatusOr<std::shared_ptr<const RegisteredRig>> rig = rigs.Get(request->registration_id());
      if (!rig.ok()) return rig.status();
      *response->mutable_registration() = RegisteredRigToProto(**rig);
      return absl::OkStatus();
    }
    if (request->object_id() <= 0 || request->rig_name().empty()) {
      return absl::InvalidArgumentError("give registration_id, or object_id and rig_name");
    }
    std::shared_ptr<const RegisteredRig> rig = rigs.Latest(request->object_id(), request->rig_name());
    if (!rig) {
      return absl::NotFoundError(absl::StrCat("rig '", request->rig_name(), "' has no registration for object ",
                                              request->object_id()));
    }
    *response->mutable_registration() = RegisteredRigToProto(*rig);
    return absl::OkStatus();
  });
}

grpc::ServerUnaryReactor* ObjectServiceImpl::ListRigRegistrations(grpc::CallbackServerContext* context,
                                                                  const pb::ListRigRegistrationsRequest* request,
                                                                  pb::ListRigRegistrationsResponse* response) {
  return HandleUnaryOnPool(context, s_, Role::kRead, "ListRigRegistrations", [this, request, response]() -> absl::Status {
    absl::StatusOr<std::vector<RegisteredRig>> rigs =
        s_.coordinator->rigs().List(request->object_id(), request->include_history());
    if (!rigs.ok()) return rigs.status();
    for (const RegisteredRig& rig : *rigs) *response->add_registrations() = RegisteredRigToProto(rig);
    return absl::OkStatus();
  });
}

}  // namespace surfmap
