// The JSON a stored probe command carries (commands.command_json): the plan's
// ProbeCommand, so a restarted server hands out exactly what was planned.
#pragma once

#include <string>

#include "absl/status/statusor.h"
#include "server/plan/probe_command.h"

namespace surfmap {

std::string ProbeCommandToJson(const ProbeCommand& command);
absl::StatusOr<ProbeCommand> ProbeCommandFromJson(const std::string& json);

}  // namespace surfmap
