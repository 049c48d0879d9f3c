// Reachability as JSON, as a job's stored parameters and the plan keep it:
// {"approach_direction": [x,y,z] | null, "max_angle_deg": a,
//  "support_point": [x,y,z] | null, "support_normal": [x,y,z] | null,
//  "support_clearance_mm": c}.
#pragma once

#include <nlohmann/json.hpp>
#include "absl/status/statusor.h"
#include "server/plan/reachability.h"

namespace surfmap {

nlohmann::json ReachabilityToJson(const Reachability& reach);
// INVALID_ARGUMENT naming the key for a malformed object or invalid values
// (Reachability::IsValid). Missing keys take the defaults.
absl::StatusOr<Reachability> ReachabilityFromJson(const nlohmann::json& json);

}  // namespace surfmap
