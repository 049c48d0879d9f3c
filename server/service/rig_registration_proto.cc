#include "server/service/rig_registration_proto.h"

#include "server/service/proto_conversion.h"

namespace surfmap {

pb::Quaternion QuaternionToProto(const Eigen::Quaterniond& q) {
  pb::Quaternion out;
  out.set_w(q.w());
  out.set_x(q.x());
  out.set_y(q.y());
  out.set_z(q.z());
  return out;
}

pb::RigRegistration RegisteredRigToProto(const RegisteredRig& rig) {
  pb::RigRegistration out;
  out.set_registration_id(rig.record.id);
  out.set_object_id(rig.record.object_id);
  out.set_rig_name(rig.record.rig_name);
  out.set_version(rig.record.version);
  *out.mutable_object_pose()->mutable_rotation() = QuaternionToProto(rig.registration.object_rotation);
  *out.mutable_object_pose()->mutable_translation_mm() = ToProto(rig.registration.object_translation_mm);
  out.set_tip_radius_mm(rig.registration.tip_radius_mm);
  *out.mutable_sensor_rotation() = QuaternionToProto(rig.registration.sensor_rotation);
  *out.mutable_created() = TimestampFromUnixMs(rig.record.created_unix_ms);
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

}  // namespace surfmap
