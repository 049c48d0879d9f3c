#include "server/plan/plan_journal.h"

#include <gtest/gtest.h>

#include <deque>

#include "server/plan/plan_test_support.h"

namespace surfmap {
namespace {

using testing::Pointers;
using testing::SynthesiseFit;
using testing::TwoMaterialPlate;

void Drain(SamplingPlan &plan, std::deque<ProbeCommand> *out) {
  while (std::optional<ProbeCommand> c = plan.NextCommand()) {
    if (out != nullptr) out->push_back(*c);
  }
}

TEST(PlanJournalTest, EntriesRoundTripExactly) {
  PlanJournalEntry fit;
  fit.sequence = 41;
  fit.fit.mu = 0.1 + 0.2;  // not representable in few digits
  fit.fit.mu_std = 1.0 / 3.0;
  fit.fit.reflection = {0.6123456789012345, -0.25};
  fit.fit.sigma = 0.11;
  absl::StatusOr<PlanJournalEntry> back = PlanJournalEntryFromJson(PlanJournalEntryToJson(fit));
  ASSERT_TRUE(back.ok()) << back.status();
  EXPECT_EQ(back->kind, PlanJournalEntry::Kind::kFit);
  EXPECT_EQ(back->sequence, 41u);
  EXPECT_EQ(back->fit.mu, fit.fit.mu);
  EXPECT_EQ(back->fit.mu_std, fit.fit.mu_std);
  EXPECT_EQ(back->fit.reflection, fit.fit.reflection);
  EXPECT_EQ(back->fit.sigma, fit.fit.sigma);

  PlanJournalEntry failure;
  failure.kind = PlanJournalEntry::Kind::kFailure;
  failure.sequence = 7;
  failure.reason = "contact lost \"twice\"";
  back = PlanJournalEntryFromJson(PlanJournalEntryToJson(failure));
  ASSERT_TRUE(back.ok()) << back.status();
  EXPECT_EQ(back->kind, PlanJournalEntry::Kind::kFailure);
  EXPECT_EQ(back->reason, failure.reason);
  EXPECT_FALSE(back->issued_after.has_value()) << "no count unless the service set one";

  failure.issued_after = 3;
  back = PlanJournalEntryFromJson(PlanJournalEntryToJson(failure));
  ASSERT_TRUE(back.ok()) << back.status();
  EXPECT_EQ(back->issued_after, 3);
}

TEST(PlanJournalTest, MalformedEntriesNameTheProblem) {
  const std::pair<const char *, const char *> cases[] = {
      {"[1,2]", "not a JSON object"},
      {R"({"sequence":1})", "\"op\""},
      {R"({"op":"fit","sequence":-1,"fit":{}})", "\"sequence\""},
      {R"({"op":"fit","sequence":1})", "\"fit\""},
      {R"({"op":"fit","sequence":1,"fit":{"mu":0.3,"mu_std":0,"sigma":"x","reflection":[]}})", "fit.sigma"},
      {R"({"op":"fit","sequence":1,"fit":{"mu":0.3,"mu_std":0,"sigma":0.1,"reflection":[0,"a"]}})", "fit.reflection"},
      {R"({"op":"failure","sequence":1})", "\"reason\""},
      {R"({"op":"teleport","sequence":1})", "teleport"},
      {R"({"op":"failure","sequence":1,"reason":"x","issued":-2})", "\"issued\""},
      {R"({"op":"failure","sequence":1,"reason":"x","issued":"2"})", "\"issued\""},
  };
  for (const auto &[text, expected] : cases) {
    absl::StatusOr<PlanJournalEntry> entry = PlanJournalEntryFromJson(text);
    ASSERT_FALSE(entry.ok()) << text;
    EXPECT_EQ(entry.status().code(), absl::StatusCode::kInvalidArgument);
    EXPECT_NE(entry.status().message().find(expected), std::string::npos) << entry.status();
  }
}

// An imported drag (not an answer to a command): its pieces join the map's,
// no site is marked measured, and a checkpoint or the journal carries it.
TEST(PlanJournalTest, ImportedDragsJoinThePiecesAndSurviveCheckpointAndJournal) {
  const auto levels = TwoMaterialPlate(3);
  const SurfaceLevel &finest = levels.back();
  SamplingPlanOptions options;
  options.mode = PlanMode::kBoundary;
  options.max_level = 3;
  options.seed = 5;
  absl::StatusOr<SamplingPlan> live = SamplingPlan::Create(Pointers(levels), options);
  ASSERT_TRUE(live.ok()) << live.status();
  Drain(*live, nullptr);
  const std::string checkpoint = live->SaveJson();
  const int vertices = static_cast<int>(finest.limit_positions.size());

  const Eigen::Vector3d at = finest.limit_positions[vertices / 2];
  PlanJournalEntry imported;
  imported.kind = PlanJournalEntry::Kind::kImport;
  imported.line = PointLineSample(at, SynthesiseFit(at, vertices / 2));
  imported.position = at;
  const std::string text = PlanJournalEntryToJson(imported);
  absl::StatusOr<PlanJournalEntry> back = PlanJournalEntryFromJson(text);
  ASSERT_TRUE(back.ok()) << back.status();
  EXPECT_EQ(back->kind, PlanJournalEntry::Kind::kImport);
  EXPECT_EQ(back->position, at);
  ASSERT_TRUE(back->line.has_value());
  ASSERT_TRUE(ApplyPlanJournalEntry(*back, *live).ok());
  Drain(*live, nullptr);

  auto imported_pieces = [vertices](const SamplingPlan &plan) {
    int n = 0;
    for (const MapPiece &p : plan.MeasuredPieces()) n += p.drag >= vertices;
    return n;
  };
  EXPECT_EQ(imported_pieces(*live), 1);
  EXPECT_EQ(live->ImportedCount(), 1);
  EXPECT_EQ(live->Progress().measured, 0);

  absl::StatusOr<SamplingPlan> replayed = SamplingPlan::Restore(checkpoint, Pointers(levels));
  ASSERT_TRUE(replayed.ok()) << replayed.status();
  ASSERT_TRUE(ApplyPlanJournalEntry(*PlanJournalEntryFromJson(text), *replayed).ok());
  Drain(*replayed, nullptr);
  EXPECT_EQ(replayed->SaveJson(), live->SaveJson());
  absl::StatusOr<SamplingPlan> restored = SamplingPlan::Restore(live->SaveJson(), Pointers(levels));
  ASSERT_TRUE(restored.ok()) << restored.status();
  EXPECT_EQ(imported_pieces(*restored), 1);

  PlanJournalEntry no_line;
  no_line.kind = PlanJournalEntry::Kind::kImport;
  EXPECT_FALSE(ApplyPlanJournalEntry(no_line, *live).ok());
  EXPECT_FALSE(PlanJournalEntryFromJson(R"({"op":"import","sequence":0,"line":{}})").ok());
}

class PlanJournalReplayTest : public ::testing::TestWithParam<PlanMode> {};

// A checkpoint plus the journal after it, replayed with a drain after each
// entry (as the service does), is the plan an uninterrupted run reached.
TEST_P(PlanJournalReplayTest, CheckpointPlusReplayEqualsTheLivePlan) {
  const auto levels = TwoMaterialPlate(3);
  const SurfaceLevel &finest = levels.back();
  SamplingPlanOptions options;
  options.mode = GetParam();
  options.max_level = 3;
  options.threshold = 1.0;
  options.seed = 99;
  options.sample_budget = GetParam() == PlanMode::kUncertainty ? 90 : 0;
  options.max_retries = 1;

  absl::StatusOr<SamplingPlan> live = SamplingPlan::Create(Pointers(levels), options);
  ASSERT_TRUE(live.ok()) << live.status();
  std::deque<ProbeCommand> outstanding;
  Drain(*live, &outstanding);

  const int checkpoint_after = 17;
  std::string checkpoint;
  std::vector<std::string> journal;
  int answers = 0, failures = 0;
  while (!outstanding.empty()) {
    // Answer the third-oldest command first: rigs finish out of order.
    const size_t pick = std::min<size_t>(2, outstanding.size() - 1);
    const ProbeCommand c = outstanding[pick];
    outstanding.erase(outstanding.begin() + static_cast<long>(pick));
    PlanJournalEntry entry;
    entry.sequence = c.sequence;
    if (answers % 9 == 4) {
      entry.kind = PlanJournalEntry::Kind::kFailure;
      entry.reason = "probe slipped";
      ++failures;
    } else {
      entry.fit = SynthesiseFit(finest.limit_positions[c.site.vertex], c.site.vertex);
    }
    ASSERT_TRUE(ApplyPlanJournalEntry(entry, *live).ok());
    Drain(*live, &outstanding);
    ++answers;
    if (answers == checkpoint_after) {
      checkpoint = live->SaveJson();
    } else if (answers > checkpoint_after) {
      journal.push_back(PlanJournalEntryToJson(entry));
    }
  }
  ASSERT_GT(journal.size(), 30u);
  ASSERT_GT(failures, 3);

  absl::StatusOr<SamplingPlan> replayed = SamplingPlan::Restore(checkpoint, Pointers(levels));
  ASSERT_TRUE(replayed.ok()) << replayed.status();
  for (const std::string &text : journal) {
    absl::StatusOr<PlanJournalEntry> entry = PlanJournalEntryFromJson(text);
    ASSERT_TRUE(entry.ok()) << entry.status();
    ASSERT_TRUE(ApplyPlanJournalEntry(*entry, *replayed).ok()) << text;
    Drain(*replayed, nullptr);
  }
  EXPECT_EQ(replayed->SaveJson(), live->SaveJson());
  EXPECT_TRUE(replayed->IsComplete());
}

INSTANTIATE_TEST_SUITE_P(Modes, PlanJournalReplayTest,
                         ::testing::Values(PlanMode::kAdaptive, PlanMode::kUncertainty, PlanMode::kUniform),
                         [](const auto &info) { return std::string(PlanModeName(info.param)); });

TEST(PlanJournalTest, ApplyingAnAnswerTwiceIsRejected) {
  const auto levels = TwoMaterialPlate(1);
  SamplingPlanOptions options;
  options.max_level = 1;
  absl::StatusOr<SamplingPlan> plan = SamplingPlan::Create(Pointers(levels), options);
  ASSERT_TRUE(plan.ok()) << plan.status();
  std::optional<ProbeCommand> c = plan->NextCommand();
  ASSERT_TRUE(c.has_value());
  PlanJournalEntry entry;
  entry.sequence = c->sequence;
  entry.fit = SynthesiseFit(levels.back().limit_positions[c->site.vertex], c->site.vertex);
  ASSERT_TRUE(ApplyPlanJournalEntry(entry, *plan).ok());
  EXPECT_EQ(ApplyPlanJournalEntry(entry, *plan).code(), absl::StatusCode::kNotFound);
}

}  // namespace
}  // namespace surfmap
