// The sampling plan as the store keeps it: a checkpoint (SamplingPlan::SaveJson)
// plus a journal of the answers recorded after it (plan_journal.h). Appending
// a small entry per trace instead of rewriting the plan keeps an accepted
// trace's write O(1) in the plan's size; a checkpoint now and then keeps the
// replay at start-up short.
#pragma once

#include <vector>

#include "absl/status/statusor.h"
#include "server/mesh/loop_surface.h"
#include "server/plan/sampling_plan.h"
#include "storage/records.h"

namespace surfmap {

// The checkpoint with the journal replayed: each entry applied, then as many
// commands issued as the service issued after it (the entry's issued_after;
// every command the plan can issue for entries written before the
// lookahead). DATA_LOSS naming the job and revision if an entry does not
// parse, does not apply, or the plan cannot issue what the entry says was
// issued.
absl::StatusOr<SamplingPlan> RestoreStoredPlan(const PlanRecord& record, std::vector<const SurfaceLevel*> levels);

// Journal entries allowed after a checkpoint before the service writes a new
// one: a quarter of the plan's sites (at least 64), so a checkpoint's cost,
// proportional to the sites, is spread over as many traces, and a replay
// applies at most that many entries.
int CheckpointInterval(const SamplingPlan& plan);

}  // namespace surfmap
