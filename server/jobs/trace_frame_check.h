// Is a refused trace in another frame than the one its rig stated? Run after
// a plausibility check (trace_plausibility.h) refused a trace, when the rig
// has a registration for the object: the trace is read in every other frame
// (server/frames/rig_frames.h: the object's, the rig's base frame, the base
// frame with sensor-frame forces, and the registration applied backwards).
// When, as stated, samples stray from the commanded site or the mean force
// (forward and reverse passes, where friction cancels) is off the commanded
// normal, but read in another frame both fit the command, the refusal
// becomes "implausible trace: frame: ..." naming both frames and the numbers.
// Otherwise the original refusal stands (its message unchanged).
#pragma once

#include "absl/status/status.h"
#include "server/estimate/drag_trace.h"
#include "server/frames/rig_frames.h"
#include "server/jobs/rig_registrations.h"
#include "server/jobs/trace_plausibility.h"
#include "server/plan/probe_command.h"

namespace surfmap {

absl::Status ExplainWrongFrame(const absl::Status& refusal, const DragTrace& as_sent, TraceFrame stated,
                               const RegisteredRig* rig, const ProbeCommand& command, const TraceLimits& limits);

// The API's spelling of a frame, for messages ("TRACE_FRAME_RIG_BASE").
const char* TraceFrameEnumName(TraceFrame frame);

}  // namespace surfmap
