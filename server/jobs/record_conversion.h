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
#include "server/jobs/rig_registrations.h"
#include "storage/records.h"

namespace surfmap {

// Unix milliseconds now (system clock).
int64_t UnixMillisNow();

// A fit as the store keeps it (headline numbers as columns, the whole result
// as JSON, the estimator and its options for provenance).
NewFit NewFitOf(const TraceFit& fit, const FitOptions& options);

// The commands the plan can issue now, as new store commands: all of them,
// or, for a plan that decides at issue (SamplingPlan::DecidesAtIssue), until
// `keep_issued` of its commands are issued and unanswered (the lookahead,
// command_lookahead.h).
std::vector<NewCommand> DrainCommands(SamplingPlan& plan, int keep_issued);

NewEvent Event(const std::string& kind, const nlohmann::json& detail);

// A leased command (or none) with its probe decoded.
struct LeaseOutcome {
  std::optional<CommandRecord> record;
  std::optional<ProbeCommand> command;  // decoded record->command_json
  bool job_finished = false;            // the requested job is completed or cancelled
  int64_t retry_after_ms = 0;           // when nothing is ready
  // The command in the leasing rig's base frame, when the rig has a
  // registration for the job's object (ProbeProtocol fills it in).
  std::optional<RigFrameCommand> rig_frame;
  std::shared_ptr<const RegisteredRig> rig_registration;  // the one rig_frame was computed with
};
// No command: ask again after a short while. DATA_LOSS if the stored command
// cannot be decoded.
absl::StatusOr<LeaseOutcome> LeaseOutcomeOf(std::optional<CommandRecord> leased);

}  // namespace surfmap
