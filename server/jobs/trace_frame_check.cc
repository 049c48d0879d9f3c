#include "server/jobs/trace_frame_check.h"

#include <functional>
#include <string>
#include <vector>

#include "absl/strings/str_format.h"

namespace surfmap {
namespace {

const char* Describe(TraceFrame frame) {
  switch (frame) {
    case TraceFrame::kObject: return "the object's frame";
    case TraceFrame::kRigBase: return "the rig's base frame";
    case TraceFrame::kRigBaseSensorForces: return "the rig's base frame with forces in the F/T sensor's frame";
  }
  return "?";
}

}  // namespace

const char* TraceFrameEnumName(TraceFrame frame) {
  switch (frame) {
    case TraceFrame::kObject: return "TRACE_FRAME_OBJECT";
    case TraceFrame::kRigBase: return "TRACE_FRAME_RIG_BASE";
    case TraceFrame::kRigBaseSensorForces: return "TRACE_FRAME_RIG_BASE_SENSOR_FORCES";
  }
  return "?";
}

absl::Status ExplainWrongFrame(const absl::Status& refusal, const DragTrace& as_sent, TraceFrame stated,
                               const RegisteredRig* rig, const ProbeCommand& command, const TraceLimits& limits) {
  if (rig == nullptr || PlausibilityCheckName(refusal).empty()) return refusal;
  const RigRegistration& r = rig->registration;
  const double reach = command.probe.segment_length_mm + limits.max_offset_mm;
  auto fits = [&](const FrameFit& f) {
    return f.max_offset_mm <= reach && f.force_angle_deg <= limits.max_normal_deg;
  };
  const FrameFit as_stated = MeasureFrameFit(TraceToObjectFrame(as_sent, stated, r), command.position, command.normal);
  if (fits(as_stated)) return refusal;  // where it should be: the frame is not what is wrong

  struct Candidate {
    std::string name;    // for the message
    std::string advice;  // what to send instead
    std::function<DragTrace()> read;
  };
  std::vector<Candidate> candidates;
  for (TraceFrame f : {TraceFrame::kRigBase, TraceFrame::kRigBaseSensorForces, TraceFrame::kObject}) {
    if (f == stated) continue;
    candidates.push_back({Describe(f), absl::StrFormat("send it with frame = %s", TraceFrameEnumName(f)),
                          [&as_sent, f, &r] { return TraceToObjectFrame(as_sent, f, r); }});
  }
  candidates.push_back({"the object's frame converted with the INVERSE of the registration",
                        "convert object -> base with p_base = R p_object + t (not its inverse), or send the "
                        "object-frame data as TRACE_FRAME_OBJECT",
                        [&as_sent, &r] { return InverseRegisteredTraceToObjectFrame(as_sent, r); }});
  for (const Candidate& c : candidates) {
    const FrameFit other = MeasureFrameFit(c.read(), command.position, command.normal);
    if (!fits(other)) continue;
    return absl::InvalidArgumentError(absl::StrFormat(
        "implausible trace: frame: the trace looks like it is in %s, not in %s as stated (%s): as sent, the "
        "farthest sample is %.1f mm from the commanded site and the mean force is %.1f deg from the commanded "
        "normal; read in %s with registration %d (rig '%s', version %d), %.1f mm and %.1f deg (limits %.1f mm, "
        "%.1f deg); %s. The check that refused it as sent: %s",
        c.name, Describe(stated), TraceFrameEnumName(stated), as_stated.max_offset_mm, as_stated.force_angle_deg,
        c.name, rig->record.id, rig->record.rig_name, rig->record.version, other.max_offset_mm, other.force_angle_deg,
        reach, limits.max_normal_deg, c.advice, PlausibilityCheckName(refusal)));
  }
  return refusal;
}

}  // namespace surfmap
