#include "server/jobs/stored_plan.h"

#include <algorithm>

#include "absl/strings/str_cat.h"
#include "server/plan/plan_journal.h"

namespace surfmap {

namespace {

absl::Status IssueAsStored(const PlanJournalEntry& entry, SamplingPlan& plan) {
  if (!entry.issued_after) {
    while (plan.NextCommand().has_value()) {
    }
    return absl::OkStatus();
  }
  for (int i = 0; i < *entry.issued_after; ++i) {
    if (!plan.NextCommand().has_value()) {
      return absl::DataLossError(absl::StrCat("the service issued ", *entry.issued_after,
                                              " commands after it, the replayed plan only ", i));
    }
  }
  return absl::OkStatus();
}

}  // namespace

absl::StatusOr<SamplingPlan> RestoreStoredPlan(const PlanRecord& record, std::vector<const SurfaceLevel*> levels) {
  absl::StatusOr<SamplingPlan> plan = SamplingPlan::Restore(record.plan_json, std::move(levels));
  if (!plan.ok()) return plan.status();
  const int64_t first_revision = record.revision - static_cast<int64_t>(record.journal.size()) + 1;
  for (size_t i = 0; i < record.journal.size(); ++i) {
    absl::StatusOr<PlanJournalEntry> entry = PlanJournalEntryFromJson(record.journal[i]);
    absl::Status applied = entry.ok() ? ApplyPlanJournalEntry(*entry, *plan) : entry.status();
    if (applied.ok()) applied = IssueAsStored(*entry, *plan);
    if (!applied.ok()) {
      return absl::DataLossError(absl::StrCat("plan of job ", record.job_id, ": journal entry at revision ",
                                              first_revision + static_cast<int64_t>(i),
                                              " cannot be replayed: ", applied.message()));
    }
  }
  return plan;
}

int CheckpointInterval(const SamplingPlan& plan) { return std::max(64, plan.SiteCount() / 4); }

}  // namespace surfmap
