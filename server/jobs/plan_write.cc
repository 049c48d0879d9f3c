#include "server/jobs/plan_write.h"

#include "server/jobs/record_conversion.h"
#include "server/jobs/stored_plan.h"

namespace surfmap {

PlanWrite TakePlanChangeLocked(JobRuntime& runtime, const PlanJournalEntry& change, int keep_issued) {
  PlanWrite write;
  write.new_commands = DrainCommands(runtime.plan, keep_issued);
  // Writes of one job are queued in order under its lock and committed in
  // queue order, so this write's base is the revision the previous one made.
  write.expected_revision = runtime.plan_revision++;
  const bool complete = runtime.plan.IsComplete();
  if (complete || runtime.journal_entries + 1 >= CheckpointInterval(runtime.plan)) {
    write.checkpoint_json = runtime.plan.SaveJson();
    runtime.journal_entries = 0;
  } else {
    PlanJournalEntry entry = change;
    entry.issued_after = static_cast<int>(write.new_commands.size());  // a replay issues as many
    write.journal_entry = PlanJournalEntryToJson(entry);
    runtime.journal_entries++;
  }
  if (complete && !IsFinalJobState(runtime.state)) {
    write.new_job_state = JobState::kCompleted;
    runtime.state = JobState::kCompleted;
  }
  return write;
}

}  // namespace surfmap
