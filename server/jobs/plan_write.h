// What one answer to a job's plan (a trace, a failure, an import), already
// applied to runtime.plan under the job's lock, writes to the store: a
// journal entry, or a checkpoint of the whole plan every CheckpointInterval
// entries and when the plan completes; the commands the plan issued; the job
// completing. Shared by ProbeProtocol and TraceImporter.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "server/jobs/job_runtime.h"
#include "server/plan/plan_journal.h"
#include "storage/records.h"

namespace surfmap {

struct PlanWrite {
  std::string checkpoint_json;
  std::string journal_entry;
  int64_t expected_revision = 0;
  std::vector<NewCommand> new_commands;
  std::optional<JobState> new_job_state;

  // Into an AcceptTraceRequest or a FailCommandRequest (same field names).
  template <typename Request>
  void MoveInto(Request& request) && {
    request.new_plan_json = std::move(checkpoint_json);
    request.plan_journal_entry = std::move(journal_entry);
    request.expected_plan_revision = expected_revision;
    request.new_commands = std::move(new_commands);
    request.new_job_state = new_job_state;
  }
};

// `keep_issued`: the commands to keep issued ahead
// (CommandLookahead::CommandsAhead, read before the job's lock).
PlanWrite TakePlanChangeLocked(JobRuntime& runtime, const PlanJournalEntry& change, int keep_issued)
    ABSL_EXCLUSIVE_LOCKS_REQUIRED(runtime.mu);

}  // namespace surfmap
