#include "server/service/rig_registration_proto.h"

#include "server/service/proto_conversion.h"

namespace surfmap {

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

}  // namespace surfmap
