#include "server/jobs/stored_plan.h"

#include <gtest/gtest.h>

#include <deque>

#include "server/jobs/record_conversion.h"
#include "server/plan/plan_journal.h"
#include "server/plan/plan_test_support.h"

namespace surfmap {
namespace {

using testing::Pointers;
using testing::SynthesiseFit;
using testing::TwoMaterialPlate;

SamplingPlanOptions BoundaryOptions() {
  SamplingPlanOptions options;
  options.mode = PlanMode::kBoundary;
  options.max_level = 3;
  options.seed = 17;
  options.coverage_skip_share = 0.25;
  return options;
}

// What the service does with a job that decides at issue: after every answer
// it issues commands until `keep_issued` are outstanding, and journals how many
// it issued. A restart (checkpoint + journal) must give the same plan, and no
// more commands than the lookahead may ever be outstanding.
TEST(StoredPlanTest, ReplayIssuesWhatTheServiceIssuedAfterEachAnswer) {
  const auto levels = TwoMaterialPlate(3);
  const SurfaceLevel& finest = levels.back();
  absl::StatusOr<SamplingPlan> live = SamplingPlan::Create(Pointers(levels), BoundaryOptions());
  ASSERT_TRUE(live.ok()) << live.status();
  ASSERT_TRUE(live->DecidesAtIssue());

  const int kRigs = 2;
  EXPECT_EQ(static_cast<int>(DrainCommands(*live, kRigs).size()), kRigs);
  EXPECT_GT(live->Progress().pending, 10) << "the rest of the coarse pass waits in the plan";

  PlanRecord stored;
  stored.job_id = 3;
  int answers = 0, most_outstanding = 0, lookahead = kRigs;
  while (!live->IsComplete()) {
    ASSERT_GT(live->OutstandingCount(), 0) << "a plan with work left always has a command issued";
    // Answer the newest outstanding command (rigs finish out of order).
    std::uint64_t newest = 0;
    for (const SiteRecord& site : live->Sites()) {
      if (site.state == SiteState::kIssued) newest = std::max(newest, site.sequence);
    }
    const SiteRecord* answered = nullptr;
    for (const SiteRecord& site : live->Sites()) {
      if (site.state == SiteState::kIssued && site.sequence == newest) answered = live->FindSite(site.site.vertex);
    }
    ASSERT_NE(answered, nullptr);
    PlanJournalEntry entry;
    entry.sequence = newest;
    entry.fit = SynthesiseFit(finest.limit_positions[answered->site.vertex], answered->site.vertex);
    ASSERT_TRUE(ApplyPlanJournalEntry(entry, *live).ok());
    // A third rig joins half-way: the lookahead grows.
    if (++answers == 20) lookahead = kRigs + 1;
    entry.issued_after = static_cast<int>(DrainCommands(*live, lookahead).size());
    most_outstanding = std::max(most_outstanding, live->OutstandingCount());
    if (answers == 5) {
      stored.plan_json = live->SaveJson();
    } else if (answers > 5) {
      stored.journal.push_back(PlanJournalEntryToJson(entry));
    }
  }
  stored.revision = 1 + static_cast<int64_t>(stored.journal.size());
  EXPECT_EQ(most_outstanding, kRigs + 1);
  ASSERT_GT(stored.journal.size(), 20u);

  absl::StatusOr<SamplingPlan> replayed = RestoreStoredPlan(stored, Pointers(levels));
  ASSERT_TRUE(replayed.ok()) << replayed.status();
  EXPECT_EQ(replayed->SaveJson(), live->SaveJson());
}

TEST(StoredPlanTest, AJournalThatClaimsMoreCommandsThanThePlanCanIssueIsDataLoss) {
  const auto levels = TwoMaterialPlate(3);
  const SurfaceLevel& finest = levels.back();
  absl::StatusOr<SamplingPlan> plan = SamplingPlan::Create(Pointers(levels), BoundaryOptions());
  ASSERT_TRUE(plan.ok()) << plan.status();
  std::vector<NewCommand> first = DrainCommands(*plan, 1);
  ASSERT_EQ(first.size(), 1u);
  PlanRecord stored;
  stored.job_id = 9;
  stored.plan_json = plan->SaveJson();
  const SiteRecord* site = nullptr;
  for (const SiteRecord& s : plan->Sites()) {
    if (s.state == SiteState::kIssued) site = plan->FindSite(s.site.vertex);
  }
  ASSERT_NE(site, nullptr);
  PlanJournalEntry entry;
  entry.sequence = site->sequence;
  entry.fit = SynthesiseFit(finest.limit_positions[site->site.vertex], site->site.vertex);
  entry.issued_after = 100'000;
  stored.journal.push_back(PlanJournalEntryToJson(entry));
  stored.revision = 2;
  absl::StatusOr<SamplingPlan> replayed = RestoreStoredPlan(stored, Pointers(levels));
  ASSERT_FALSE(replayed.ok());
  EXPECT_EQ(replayed.status().code(), absl::StatusCode::kDataLoss);
  EXPECT_NE(replayed.status().message().find("job 9"), std::string::npos) << replayed.status();
  EXPECT_NE(replayed.status().message().find("issued 100000"), std::string::npos) << replayed.status();
}

// Entries written before the lookahead carry no count: the service issued
// every command it could after them, and so does the replay.
TEST(StoredPlanTest, EntriesWithoutACountAreFollowedByEveryCommand) {
  const auto levels = TwoMaterialPlate(3);
  const SurfaceLevel& finest = levels.back();
  absl::StatusOr<SamplingPlan> live = SamplingPlan::Create(Pointers(levels), BoundaryOptions());
  ASSERT_TRUE(live.ok()) << live.status();
  std::vector<NewCommand> all = DrainCommands(*live, 1'000'000);
  ASSERT_GT(all.size(), 10u);
  PlanRecord stored;
  stored.plan_json = live->SaveJson();
  for (const SiteRecord& s : live->Sites()) {
    if (s.state != SiteState::kIssued || stored.journal.size() >= 3) continue;
    PlanJournalEntry entry;
    entry.sequence = s.sequence;
    entry.fit = SynthesiseFit(finest.limit_positions[s.site.vertex], s.site.vertex);
    ASSERT_TRUE(ApplyPlanJournalEntry(entry, *live).ok());
    DrainCommands(*live, 1'000'000);
    stored.journal.push_back(PlanJournalEntryToJson(entry));
  }
  stored.revision = 1 + static_cast<int64_t>(stored.journal.size());
  absl::StatusOr<SamplingPlan> replayed = RestoreStoredPlan(stored, Pointers(levels));
  ASSERT_TRUE(replayed.ok()) << replayed.status();
  EXPECT_EQ(replayed->SaveJson(), live->SaveJson());
}

// Plans whose commands are fixed in advance issue everything at once, whatever
// the lookahead: their order cannot use what earlier drags found.
TEST(StoredPlanTest, PlansThatDoNotDecideAtIssueAreIssuedWhole) {
  const auto levels = TwoMaterialPlate(3);
  SamplingPlanOptions options = BoundaryOptions();
  options.mode = PlanMode::kUniform;
  options.coverage_skip_share = 0.0;
  absl::StatusOr<SamplingPlan> plan = SamplingPlan::Create(Pointers(levels), options);
  ASSERT_TRUE(plan.ok()) << plan.status();
  EXPECT_FALSE(plan->DecidesAtIssue());
  const std::vector<NewCommand> commands = DrainCommands(*plan, 1);
  EXPECT_GT(commands.size(), 1u);
  EXPECT_EQ(plan->Progress().pending, 0);
}

}  // namespace
}  // namespace surfmap
