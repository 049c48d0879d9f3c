// Rig registrations and frames: proto <-> domain (server/frames).
#pragma once

#include "absl/status/statusor.h"
#include "proto/surfmap/v1/surfmap.pb.h"
#include "server/frames/rig_registration.h"
#include "server/jobs/rig_registrations.h"

namespace surfmap {

namespace pb = ::surfmap::v1;

pb::Quaternion QuaternionToProto(const Eigen::Quaterniond& q);
pb::RigRegistration RegisteredRigToProto(const RegisteredRig& rig);
// Validates (MakeRigRegistration: field names as in the API); an unset
// sensor_rotation is the identity (the sensor aligned with the base).
absl::StatusOr<RigRegistration> RigRegistrationFromProto(const pb::RigRegistration& in);

}  // namespace surfmap
