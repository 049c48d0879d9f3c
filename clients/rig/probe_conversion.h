// Between the API's probe messages and the RigDriver's domain types.
#pragma once

#include "absl/status/statusor.h"
#include "clients/sim/rig/rig_driver.h"
#include "proto/surfmap/v1/surfmap.pb.h"
#include "server/estimate/drag_trace.h"

namespace surfmap::rig {

// The driver request of a leased command. Zero probe parameters (an old or
// sparse server) take the paper's defaults (20 mm, 10 mm/s, 5 N).
// INVALID_ARGUMENT (via ValidateProbeRequest) naming the bad field.
absl::StatusOr<ProbeRequest> ProbeRequestFromCommand(const surfmap::v1::ProbeCommand& command);

}  // namespace surfmap::rig
