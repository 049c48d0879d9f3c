// Rig registrations and trace frames: the API's protobuf form <-> the domain
// (server/frames). One conversion for the server and the rig client.
#pragma once

#include <Eigen/Geometry>

#include "absl/status/statusor.h"
#include "proto/surfmap/v1/surfmap.pb.h"
#include "server/frames/rig_frames.h"
#include "server/frames/rig_registration.h"

namespace surfmap {

::surfmap::v1::Quaternion QuaternionToProto(const Eigen::Quaterniond& q);

// Validates (MakeRigRegistration: field names as in the API); an unset
// sensor_rotation is the identity (the sensor aligned with the base).
absl::StatusOr<RigRegistration> RigRegistrationFromProto(const ::surfmap::v1::RigRegistration& in);

// TRACE_FRAME_UNSPECIFIED is the object's frame (rigs from before frames
// existed); a value this build does not know is INVALID_ARGUMENT naming it.
absl::StatusOr<TraceFrame> TraceFrameFromProto(::surfmap::v1::TraceFrame frame);
::surfmap::v1::TraceFrame TraceFrameToProto(TraceFrame frame);

}  // namespace surfmap
