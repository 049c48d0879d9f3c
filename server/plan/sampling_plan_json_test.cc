#include <deque>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include "absl/strings/str_cat.h"
#include "server/plan/plan_test_support.h"
#include "server/plan/sampling_plan.h"

namespace surfmap {
namespace {

using testing::Drive;
using testing::IssuedRecord;
using testing::Pointers;
using testing::SynthesiseFit;
using testing::TwoMaterialPlate;

SamplingPlanOptions OptionsFor(PlanMode mode) {
  SamplingPlanOptions o;
  o.mode = mode;
  o.max_level = 3;
  o.threshold = 1.0;
  o.seed = 99;
  o.sample_budget = mode == PlanMode::kUncertainty ? 90 : 0;
  o.max_retries = 1;
  return o;
}

class SaveRestoreTest : public ::testing::TestWithParam<PlanMode> {};

TEST_P(SaveRestoreTest, RestoredPlanIssuesTheSameCommandsAsAnUninterruptedOne) {
  const auto levels = TwoMaterialPlate(3);
  const SurfaceLevel& finest = levels.back();
  const SamplingPlanOptions options = OptionsFor(GetParam());

  auto uninterrupted = SamplingPlan::Create(Pointers(levels), options);
  ASSERT_TRUE(uninterrupted.ok()) << uninterrupted.status();
  std::deque<ProbeCommand> queue_a;
  const std::vector<IssuedRecord> expected = Drive(*uninterrupted, finest, /*rigs=*/3, queue_a);
  ASSERT_GE(expected.size(), 60u);

  const int n = static_cast<int>(expected.size());
  int saved_with_outstanding = 0;
  for (int stop_after : {10, 58, n - 6}) {
    SCOPED_TRACE(stop_after);
    auto first = SamplingPlan::Create(Pointers(levels), options);
    ASSERT_TRUE(first.ok());
    std::deque<ProbeCommand> queue;  // the rigs' commands survive the restart
    std::vector<IssuedRecord> issued = Drive(*first, finest, 3, queue, stop_after);
    saved_with_outstanding += !queue.empty();
    const std::string saved = first->SaveJson();

    auto restored = SamplingPlan::Restore(saved, Pointers(levels));
    ASSERT_TRUE(restored.ok()) << restored.status();
    EXPECT_EQ(restored->SaveJson(), saved);
    EXPECT_EQ(restored->Progress().issued, static_cast<int>(queue.size()));
    const std::vector<IssuedRecord> rest = Drive(*restored, finest, 3, queue);
    issued.insert(issued.end(), rest.begin(), rest.end());
    EXPECT_EQ(issued, expected);
    EXPECT_EQ(restored->SaveJson(), uninterrupted->SaveJson());
  }
  EXPECT_GT(saved_with_outstanding, 0);  // commands were outstanding across a save
}

INSTANTIATE_TEST_SUITE_P(Modes, SaveRestoreTest,
                         ::testing::Values(PlanMode::kAdaptive, PlanMode::kUncertainty, PlanMode::kUniform),
                         [](const auto& info) { return std::string(PlanModeName(info.param)); });

TEST(SaveRestoreTest, KeepsFailuresRetriesAndCancellation) {
  const auto levels = TwoMaterialPlate(1);
  auto plan = SamplingPlan::Create(Pointers(levels), OptionsFor(PlanMode::kAdaptive));
  // max_level 3 > 1: use a shallower plan.
  SamplingPlanOptions o = OptionsFor(PlanMode::kAdaptive);
  o.max_level = 1;
  plan = SamplingPlan::Create(Pointers(levels), o);
  ASSERT_TRUE(plan.ok()) << plan.status();
  auto a = plan->NextCommand();
  ASSERT_TRUE(plan->RecordFailure(a->sequence, "contact lost").ok());
  auto b = plan->NextCommand();
  plan->Cancel();
  auto restored = SamplingPlan::Restore(plan->SaveJson(), Pointers(levels));
  ASSERT_TRUE(restored.ok()) << restored.status();
  EXPECT_FALSE(restored->NextCommand().has_value());
  const SiteRecord* r = restored->FindSite(a->site.vertex);
  ASSERT_NE(r, nullptr);
  EXPECT_EQ(r->failures, 1);
  EXPECT_EQ(r->state, SiteState::kSkipped);
  // The outstanding command is still accepted by its sequence number.
  EXPECT_TRUE(restored->RecordFit(b->sequence, SynthesiseFit(b->position, b->site.vertex)).ok());
  EXPECT_TRUE(restored->IsComplete());
}

// The stored speed key is "speed_mm_s" (as in job parameters and probe
// commands); plans saved under the old "speed_mm_per_s" still restore.
TEST(SaveRestoreTest, ReadsTheProbeSpeedUnderTheCurrentAndTheOldKey) {
  const auto levels = TwoMaterialPlate(1);
  SamplingPlanOptions o = OptionsFor(PlanMode::kAdaptive);
  o.max_level = 1;
  o.probe.speed_mm_per_s = 7.5;
  auto plan = SamplingPlan::Create(Pointers(levels), o);
  ASSERT_TRUE(plan.ok()) << plan.status();
  nlohmann::json saved = nlohmann::json::parse(plan->SaveJson());
  ASSERT_TRUE(saved["options"]["probe"].contains("speed_mm_s"));
  EXPECT_FALSE(saved["options"]["probe"].contains("speed_mm_per_s"));

  nlohmann::json old = saved;
  old["options"]["probe"].erase("speed_mm_s");
  old["options"]["probe"]["speed_mm_per_s"] = 7.5;
  auto restored = SamplingPlan::Restore(old.dump(), Pointers(levels));
  ASSERT_TRUE(restored.ok()) << restored.status();
  EXPECT_EQ(restored->SaveJson(), saved.dump());  // written back under the current key

  old["options"]["probe"].erase("speed_mm_per_s");
  auto missing = SamplingPlan::Restore(old.dump(), Pointers(levels));
  ASSERT_FALSE(missing.ok());
  EXPECT_NE(missing.status().message().find("options.probe.speed_mm_s is missing"), std::string::npos)
      << missing.status();
}

// "change_location_mm" joined options.regions later than the others: a plan
// saved without it restores with the default.
TEST(SaveRestoreTest, APlanSavedBeforeChangeLocationRestoresWithTheDefault) {
  const auto levels = TwoMaterialPlate(1);
  SamplingPlanOptions o = OptionsFor(PlanMode::kBoundary);
  o.max_level = 1;
  auto plan = SamplingPlan::Create(Pointers(levels), o);
  ASSERT_TRUE(plan.ok()) << plan.status();
  nlohmann::json saved = nlohmann::json::parse(plan->SaveJson());
  ASSERT_TRUE(saved["options"]["regions"].contains("change_location_mm"));
  saved["options"]["regions"].erase("change_location_mm");
  auto restored = SamplingPlan::Restore(saved.dump(), Pointers(levels));
  ASSERT_TRUE(restored.ok()) << restored.status();
  EXPECT_EQ(nlohmann::json::parse(restored->SaveJson())["options"]["regions"]["change_location_mm"],
            SamplingPlanOptions{}.regions.change_location_mm);
}

// A boundary plan with options `o`, saved and restored: its options as
// restored, with `erased_key` ("" for none) taken out of the saved options
// first, as a plan saved before the option existed would lack it.
absl::StatusOr<SamplingPlanOptions> RestoredOptions(SamplingPlanOptions o, const std::string& erased_key) {
  const auto levels = TwoMaterialPlate(1);
  o.max_level = 1;
  auto plan = SamplingPlan::Create(Pointers(levels), o);
  if (!plan.ok()) return plan.status();
  nlohmann::json saved = nlohmann::json::parse(plan->SaveJson());
  if (!erased_key.empty()) {
    if (!saved["options"].contains(erased_key)) {
      return absl::NotFoundError(absl::StrCat("the saved options have no ", erased_key));
    }
    saved["options"].erase(erased_key);
  }
  auto restored = SamplingPlan::Restore(saved.dump(), Pointers(levels));
  if (!restored.ok()) return restored.status();
  return restored->options();
}

// `o.*field` survives a save and restore, and a plan saved before the
// option existed (its `key` missing) restores with `before_it`.
template <typename T>
void ExpectSavedAndDefaultedBeforeIt(const SamplingPlanOptions& o, T SamplingPlanOptions::*field,
                                     const std::string& key, T before_it) {
  auto kept = RestoredOptions(o, "");
  ASSERT_TRUE(kept.ok()) << kept.status();
  EXPECT_EQ((*kept).*field, o.*field) << key;
  auto older = RestoredOptions(o, key);
  ASSERT_TRUE(older.ok()) << older.status();
  EXPECT_EQ((*older).*field, before_it) << key;
}

TEST(SaveRestoreTest, FollowBoundariesIsSavedAndAPlanSavedBeforeItRestoresWithoutIt) {
  SamplingPlanOptions o = OptionsFor(PlanMode::kBoundary);
  o.follow_boundaries = true;
  ExpectSavedAndDefaultedBeforeIt(o, &SamplingPlanOptions::follow_boundaries, "follow_boundaries", false);
}

TEST(SaveRestoreTest, ContinuationPriorIsSavedAndAPlanSavedBeforeItRestoresWithoutIt) {
  SamplingPlanOptions o = OptionsFor(PlanMode::kBoundary);
  o.continuation_prior = 0.5;
  ExpectSavedAndDefaultedBeforeIt(o, &SamplingPlanOptions::continuation_prior, "continuation_prior", 0.0);
  o.continuation_prior = 1.5;
  EXPECT_EQ(RestoredOptions(o, "").status().code(), absl::StatusCode::kInvalidArgument);
}

TEST(SaveRestoreTest, APlanSavedBeforeCoverageSkipRestoresDraggingEverySite) {
  SamplingPlanOptions o = OptionsFor(PlanMode::kBoundary);
  o.coverage_skip_share = 0.25;
  ExpectSavedAndDefaultedBeforeIt(o, &SamplingPlanOptions::coverage_skip_share, "coverage_skip_share", 0.0);
}

TEST(SaveRestoreTest, APlanSavedBeforeTheQuietCoverageSkipRestoresWithout) {
  SamplingPlanOptions o = OptionsFor(PlanMode::kBoundary);
  o.quiet_coverage_skip_share = 0.5;
  ExpectSavedAndDefaultedBeforeIt(o, &SamplingPlanOptions::quiet_coverage_skip_share, "quiet_coverage_skip_share",
                                  0.0);
}

TEST(SaveRestoreTest, APlanSavedBeforeTheBoundaryCostFollowedThePropertyRestoresWeighingByFriction) {
  SamplingPlanOptions o = OptionsFor(PlanMode::kBoundary);
  ASSERT_TRUE(o.boundary_cost_follows_property);
  ExpectSavedAndDefaultedBeforeIt(o, &SamplingPlanOptions::boundary_cost_follows_property, "boundary_cost_follows_property", false);
}

TEST(SaveRestoreTest, APlanSavedBeforeTheMisclassificationCostRestoresWeighingSquaredErrorAlone) {
  SamplingPlanOptions o = OptionsFor(PlanMode::kBoundary);
  ASSERT_GT(o.misclassification_cost, 0.0);
  ExpectSavedAndDefaultedBeforeIt(o, &SamplingPlanOptions::misclassification_cost, "misclassification_cost", 0.0);
  o.misclassification_cost = -0.01;
  EXPECT_EQ(RestoredOptions(o, "").status().code(), absl::StatusCode::kInvalidArgument);
}

TEST(SaveRestoreTest, SmallMaterialWeightIsSavedAndAPlanSavedBeforeItRestoresWeighingEveryBoundaryAlike) {
  SamplingPlanOptions o = OptionsFor(PlanMode::kBoundary);
  o.small_material_weight_max = 4.0;
  ExpectSavedAndDefaultedBeforeIt(o, &SamplingPlanOptions::small_material_weight_max, "small_material_weight_max",
                                  1.0);
  o.small_material_weight_max = 0.5;
  EXPECT_EQ(RestoredOptions(o, "").status().code(), absl::StatusCode::kInvalidArgument);
}

TEST(SaveRestoreTest, FarGainExpectedIsSavedAndAPlanSavedBeforeItRestoresCountingTheCorridorInFull) {
  SamplingPlanOptions o = OptionsFor(PlanMode::kBoundary);
  o.far_gain_expected = true;
  ExpectSavedAndDefaultedBeforeIt(o, &SamplingPlanOptions::far_gain_expected, "far_gain_expected", false);
}

TEST(SaveRestoreTest, IssueSelectedByGainIsSavedAndAPlanSavedBeforeItRestoresIssuingInThePlansOrder) {
  SamplingPlanOptions o = OptionsFor(PlanMode::kBoundary);
  o.issue_selected_by_gain = true;
  ExpectSavedAndDefaultedBeforeIt(o, &SamplingPlanOptions::issue_selected_by_gain, "issue_selected_by_gain", false);
}

TEST(SaveRestoreTest, CoarseDirectionByGainIsSavedAndAPlanSavedBeforeItRestoresWithTheKeysOrientation) {
  SamplingPlanOptions o = OptionsFor(PlanMode::kBoundary);
  o.coarse_direction_by_gain = true;
  ExpectSavedAndDefaultedBeforeIt(o, &SamplingPlanOptions::coarse_direction_by_gain, "coarse_direction_by_gain",
                                  false);
}

TEST(SaveRestoreTest, RejectsCorruptOrMismatchedState) {
  const auto levels = TwoMaterialPlate(2);
  SamplingPlanOptions o = OptionsFor(PlanMode::kAdaptive);
  o.max_level = 2;
  auto plan = SamplingPlan::Create(Pointers(levels), o);
  ASSERT_TRUE(plan.ok());
  auto c = plan->NextCommand();
  ASSERT_TRUE(plan->RecordFit(c->sequence, SynthesiseFit(c->position, c->site.vertex)).ok());
  (void)plan->NextCommand();
  const nlohmann::json good = nlohmann::json::parse(plan->SaveJson());
  ASSERT_TRUE(SamplingPlan::Restore(good.dump(), Pointers(levels)).ok());

  auto expect_error = [&](const nlohmann::json& j, const std::string& needle) {
    auto restored = SamplingPlan::Restore(j.dump(), Pointers(levels));
    ASSERT_FALSE(restored.ok()) << "accepted: " << needle;
    EXPECT_EQ(restored.status().code(), absl::StatusCode::kInvalidArgument);
    EXPECT_NE(restored.status().message().find(needle), std::string::npos) << restored.status();
  };
  EXPECT_FALSE(SamplingPlan::Restore("{not json", Pointers(levels)).ok());
  nlohmann::json j = good;
  j["version"] = 3;
  expect_error(j, "version 3");
  j = good;
  j["format"] = "something else";
  expect_error(j, "format");
  j = good;
  j.erase("next_sequence");
  expect_error(j, "next_sequence is missing");
  j = good;
  j["surface"]["vertex_counts"][2] = 10;
  expect_error(j, "surface.vertex_counts");
  j = good;
  j["sites"][0]["level"] = 1;
  expect_error(j, "sites[0].level");
  j = good;
  j["sites"][1]["vertex"] = j["sites"][0]["vertex"];
  expect_error(j, "repeats vertex");
  j = good;
  j["sites"][0]["vertex"] = 100000;
  expect_error(j, "sites[0].vertex");
  j = good;
  j["sites"][0]["state"] = "lost";
  expect_error(j, "sites[0].state");
  j = good;
  j["options"]["max_level"] = 7;
  expect_error(j, "max_level");
  // A selection rank on a site the boundary plan did not choose.
  j = good;
  j["sites"][0]["selection_rank"] = 1;
  expect_error(j, "sites[0].selection_rank 1 is not a selected site's");
  // The measured site without its fit, and with a bad one.
  for (size_t i = 0; i < good["sites"].size(); ++i) {
    if (good["sites"][i]["state"] == "measured") {
      j = good;
      j["sites"][i].erase("fit");
      expect_error(j, "fit is missing");
      j = good;
      j["sites"][i]["fit"]["reflection"] = {1.5};
      expect_error(j, "reflection");
    }
  }
  // Another surface.
  const auto other = TwoMaterialPlate(3);
  EXPECT_FALSE(SamplingPlan::Restore(good.dump(), Pointers(other)).ok());
}

}  // namespace
}  // namespace surfmap
