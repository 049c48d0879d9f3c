// Small conversions between the job layer's domain values and the store's
// records, shared by the parts of the coordinator.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>
#include "absl/status/statusor.h"
#include "server/estimate/fit_trace.h"
#include "server/plan/probe_command.h"
#include "server/plan/sampling_plan.h"
#include "storage/records.h"

namespace surfmap {

// Unix milliseconds now (system clock).
int64_t UnixMillisNow();

// A fit as the store keeps it (headline numbers as columns, the whole result
// as JSON, the estimator and its options for provenance).
NewFit NewFitOf(const TraceFit& fit, const FitOptions& options);

// Every command the plan can issue now, as new store commands.
std::vector<NewCommand> DrainCommands(SamplingPlan& plan);

NewEvent Event(const std::string& kind, const nlohmann::json& detail);

// A leased command (or none) with its probe decoded.
struct LeaseOutcome {
  std::optional<CommandRecord> record;
  std::optional<ProbeCommand> command;  // decoded record->command_json
  bool job_finished = false;            // the requested job is completed or cancelled
  int64_t retry_after_ms = 0;           // when nothing is ready
};
// No command: ask again after a short while. DATA_LOSS if the stored command
// cannot be decoded.
absl::StatusOr<LeaseOutcome> LeaseOutcomeOf(std::optional<CommandRecord> leased);

}  // namespace surfmap
