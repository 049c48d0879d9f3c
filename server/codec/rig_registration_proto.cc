#include "server/codec/rig_registration_proto.h"

#include <array>

#include "absl/strings/str_cat.h"

namespace surfmap {

namespace pb = ::surfmap::v1;

pb::Quaternion QuaternionToProto(const Eigen::Quaterniond& q) {
  pb::Quaternion out;
  out.set_w(q.w());
  out.set_x(q.x());
  out.set_y(q.y());
  out.set_z(q.z());
  return out;
}

absl::StatusOr<RigRegistration> RigRegistrationFromProto(const pb::RigRegistration& in) {
  const pb::Quaternion& r = in.object_pose().rotation();
  const pb::Vec3& t = in.object_pose().translation_mm();
  std::array<double, 4> sensor = {1, 0, 0, 0};
  if (in.has_sensor_rotation()) {
    const pb::Quaternion& s = in.sensor_rotation();
    sensor = {s.w(), s.x(), s.y(), s.z()};
  }
  return MakeRigRegistration({r.w(), r.x(), r.y(), r.z()}, Eigen::Vector3d(t.x(), t.y(), t.z()), in.tip_radius_mm(),
                             sensor);
}

absl::StatusOr<TraceFrame> TraceFrameFromProto(pb::TraceFrame frame) {
  switch (frame) {
    case pb::TRACE_FRAME_UNSPECIFIED:  // rigs from before frames existed
    case pb::TRACE_FRAME_OBJECT: return TraceFrame::kObject;
    case pb::TRACE_FRAME_RIG_BASE: return TraceFrame::kRigBase;
    case pb::TRACE_FRAME_RIG_BASE_SENSOR_FORCES: return TraceFrame::kRigBaseSensorForces;
    default: break;
  }
  return absl::InvalidArgumentError(absl::StrCat("frame: unknown value ", static_cast<int>(frame)));
}

pb::TraceFrame TraceFrameToProto(TraceFrame frame) {
  switch (frame) {
    case TraceFrame::kObject: return pb::TRACE_FRAME_OBJECT;
    case TraceFrame::kRigBase: return pb::TRACE_FRAME_RIG_BASE;
    case TraceFrame::kRigBaseSensorForces: return pb::TRACE_FRAME_RIG_BASE_SENSOR_FORCES;
  }
  return pb::TRACE_FRAME_OBJECT;  // unreachable: every enumerator is handled above
}

}  // namespace surfmap
