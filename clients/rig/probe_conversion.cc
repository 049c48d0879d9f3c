#include "clients/rig/probe_conversion.h"

#include "absl/strings/str_cat.h"

namespace surfmap::rig {

namespace pb = ::surfmap::v1;

namespace {
Eigen::Vector3d FromProto(const pb::Vec3& v) { return {v.x(), v.y(), v.z()}; }
}  // namespace

absl::StatusOr<ProbeRequest> ProbeRequestFromCommand(const pb::ProbeCommand& command) {
  ProbeRequest request;
  request.position = FromProto(command.position());
  request.normal = FromProto(command.normal());
  request.drag_direction = FromProto(command.drag_direction());
  const pb::ProbeParameters& p = command.probe();
  if (p.segment_length_mm() != 0.0) request.segment_length_mm = p.segment_length_mm();
  if (p.speed_mm_s() != 0.0) request.speed_mm_s = p.speed_mm_s();
  if (p.normal_force_n() != 0.0) request.normal_force_n = p.normal_force_n();
  request.command_id = command.command_id();
  request.job_id = command.job_id();
  request.attempt = command.attempt();
  request.site_level = command.site().level();
  request.site_vertex = command.site().vertex();
  if (command.has_lease_deadline()) {
    request.lease_deadline_unix_ms =
        command.lease_deadline().seconds() * 1000 + command.lease_deadline().nanos() / 1'000'000;
  }
  if (command.has_rig_frame()) {
    const pb::RigFrameCommand& f = command.rig_frame();
    RigFrameRequest frame;
    frame.registration_id = f.registration_id();
    frame.command.position = FromProto(f.position());
    frame.command.normal = FromProto(f.normal());
    frame.command.drag_direction = FromProto(f.drag_direction());
    frame.command.start = FromProto(f.start());
    frame.command.end = FromProto(f.end());
    for (const pb::Vec3& p : f.tool_centre_path()) frame.command.tool_centre_path.push_back(FromProto(p));
    frame.tip_radius_mm = f.tip_radius_mm();
    request.rig_frame = std::move(frame);
  }
  absl::Status valid = ValidateProbeRequest(request);
  if (!valid.ok()) {
    return absl::InvalidArgumentError(absl::StrCat("command ", command.command_id(), ": ", valid.message()));
  }
  return request;
}


}  // namespace surfmap::rig
