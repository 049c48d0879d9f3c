#include "server/plan/sampling_plan.h"

#include <algorithm>
#include <cmath>
#include <deque>
#include <map>
#include <optional>
#include <string>
#include <set>

#include <gtest/gtest.h>
#include "absl/strings/str_cat.h"
#include "server/plan/plan_test_support.h"

namespace surfmap {
namespace {

using testing::DriveToEnd;
using testing::Pointers;
using testing::SynthesiseFit;
using testing::TwoMaterialPlate;

constexpr double kCoarseCell = 100.0 / 9.0;

SamplingPlanOptions Adaptive(int max_level = 3) {
  SamplingPlanOptions o;
  o.mode = PlanMode::kAdaptive;
  o.coarsest_level = 0;
  o.max_level = max_level;
  o.threshold = 1.0;  // mu differs by 0.37 = 7.4 scales across the boundary; noise gives ~0.14
  o.seed = 42;
  return o;
}

TEST(SamplingPlanTest, AdaptiveRefinesOnlyAcrossTheBoundary) {
  const auto levels = TwoMaterialPlate(3);
  auto plan = SamplingPlan::Create(Pointers(levels), Adaptive(3));
  ASSERT_TRUE(plan.ok()) << plan.status();
  DriveToEnd(*plan, levels.back());
  ASSERT_TRUE(plan->IsComplete());

  std::vector<int> refined_per_level(4, 0);
  for (const SiteRecord& r : plan->Sites()) {
    EXPECT_EQ(r.state, SiteState::kMeasured) << "vertex " << r.site.vertex;
    if (r.origin == SiteOrigin::kInitial) {
      EXPECT_EQ(r.site.level, 0);
      continue;
    }
    ASSERT_EQ(r.origin, SiteOrigin::kRefined);
    ++refined_per_level[r.site.level];
    // It splits an edge of level k = level - 1 whose ends lie on both sides,
    // so it lies within half that level's edge width (in x) of x = 0.
    const double parent_width = kCoarseCell / std::pow(2.0, r.site.level - 1);
    const double x = levels.back().limit_positions[r.site.vertex].x();
    EXPECT_LE(std::abs(x), 0.5 * parent_width + 1e-9) << "vertex " << r.site.vertex << " level " << r.site.level;
    EXPECT_GT(r.parent_distance, 1.0);
    const double xa = levels.back().limit_positions[r.parent_a].x();
    const double xb = levels.back().limit_positions[r.parent_b].x();
    EXPECT_LT(std::min(xa, xb), 0.0);
    EXPECT_GE(std::max(xa, xb), 0.0);
  }
  // Level 1 splits every coarse edge that crosses x = 0: 6 horizontal edges
  // and 5 diagonals. Each split vertex then bisects one crossing edge per
  // level: the threshold rule refines pairwise, it does not fill in the
  // boundary line between its samples.
  EXPECT_EQ(refined_per_level[1], 11);
  EXPECT_GE(refined_per_level[2], 11);
  EXPECT_GE(refined_per_level[3], 11);
  const PlanProgress p = plan->Progress();
  EXPECT_EQ(p.levels[0].measured, 60);
  EXPECT_EQ(p.measured, 60 + refined_per_level[1] + refined_per_level[2] + refined_per_level[3]);
  EXPECT_TRUE(p.done);
  EXPECT_EQ(p.budget_left, -1);
}

TEST(SamplingPlanTest, AdaptiveOnAUniformMaterialDoesNotRefine) {
  auto levels = TwoMaterialPlate(2);
  for (auto& l : levels) {  // shift the plate right of the boundary: all sandpaper
    for (auto& p : l.limit_positions) p.x() += 200.0;
  }
  auto plan = SamplingPlan::Create(Pointers(levels), Adaptive(2));
  ASSERT_TRUE(plan.ok());
  const auto issued = DriveToEnd(*plan, levels.back());
  EXPECT_EQ(issued.size(), 60u);
}

TEST(SamplingPlanTest, UniformModeIssuesExactlyTheLevelsVertices) {
  const auto levels = TwoMaterialPlate(3);
  SamplingPlanOptions o = Adaptive(3);
  o.mode = PlanMode::kUniform;
  o.coarsest_level = 2;
  auto plan = SamplingPlan::Create(Pointers(levels), o);
  ASSERT_TRUE(plan.ok()) << plan.status();
  const auto issued = DriveToEnd(*plan, levels.back(), 3);
  std::set<int> vertices;
  for (const auto& i : issued) {
    EXPECT_EQ(i.site.level, 2);
    vertices.insert(i.site.vertex);
  }
  EXPECT_EQ(issued.size(), levels[2].limit_positions.size());
  EXPECT_EQ(vertices.size(), levels[2].limit_positions.size());
  EXPECT_EQ(*vertices.rbegin(), static_cast<int>(levels[2].limit_positions.size()) - 1);
  EXPECT_TRUE(plan->IsComplete());
}

TEST(SamplingPlanTest, BudgetIsRespectedWithSeveralRigs) {
  const auto levels = TwoMaterialPlate(3);
  SamplingPlanOptions o = Adaptive(3);
  o.sample_budget = 75;
  auto plan = SamplingPlan::Create(Pointers(levels), o);
  ASSERT_TRUE(plan.ok());
  std::deque<ProbeCommand> outstanding;
  int issued_total = 0;
  while (true) {
    while (outstanding.size() < 4) {
      auto c = plan->NextCommand();
      if (!c) break;
      outstanding.push_back(*c);
      ++issued_total;
      const PlanProgress p = plan->Progress();
      ASSERT_LE(p.measured + p.issued, 75);
    }
    if (outstanding.empty()) break;
    const auto c = outstanding.front();
    outstanding.pop_front();
    ASSERT_TRUE(plan->RecordFit(c.sequence, SynthesiseFit(levels.back().limit_positions[c.site.vertex],
                                                          c.site.vertex)).ok());
  }
  const PlanProgress p = plan->Progress();
  EXPECT_EQ(issued_total, 75);
  EXPECT_EQ(p.measured, 75);
  EXPECT_EQ(p.budget_left, 0);
  EXPECT_GT(p.skipped, 0);  // refinements proposed after the budget ran out
  EXPECT_EQ(p.pending, 0);
  EXPECT_TRUE(p.done);
  for (const auto& r : plan->Sites()) {
    if (r.state == SiteState::kSkipped) {
      EXPECT_EQ(r.reason, "sample budget used up");
    }
  }
}

TEST(SamplingPlanTest, FailuresAreRetriedUpToMaxRetriesThenFailForGood) {
  const auto levels = TwoMaterialPlate(1);
  SamplingPlanOptions o = Adaptive(1);
  o.max_retries = 2;
  auto plan = SamplingPlan::Create(Pointers(levels), o);
  ASSERT_TRUE(plan.ok());
  const int unreachable = 17;
  std::vector<int> attempts_seen;
  int other_coarse_issued = 0;
  int other_coarse_before_retry = -1;
  while (auto c = plan->NextCommand()) {
    if (c->site.vertex == unreachable) {
      attempts_seen.push_back(c->attempt);
      if (c->attempt == 2) other_coarse_before_retry = other_coarse_issued;
      ASSERT_TRUE(plan->RecordFailure(c->sequence, "out of reach of the arm").ok());
      continue;
    }
    if (c->site.level == 0) ++other_coarse_issued;
    ASSERT_TRUE(plan->RecordFit(c->sequence, SynthesiseFit(levels.back().limit_positions[c->site.vertex],
                                                           c->site.vertex)).ok());
  }
  // The retry went behind every fresh site of its level.
  EXPECT_EQ(other_coarse_before_retry, 59);
  EXPECT_EQ(attempts_seen, (std::vector<int>{1, 2, 3}));
  const SiteRecord* r = plan->FindSite(unreachable);
  ASSERT_NE(r, nullptr);
  EXPECT_EQ(r->state, SiteState::kFailed);
  EXPECT_EQ(r->failures, 3);
  EXPECT_NE(r->reason.find("out of reach of the arm"), std::string::npos) << r->reason;
  EXPECT_TRUE(plan->IsComplete());
  const PlanProgress p = plan->Progress();
  EXPECT_EQ(p.failed, 1);
  EXPECT_EQ(p.levels[0].measured, 59);
}

TEST(SamplingPlanTest, NextCommandWaitsForOutstandingMeasurements) {
  const auto levels = TwoMaterialPlate(2);
  auto plan = SamplingPlan::Create(Pointers(levels), Adaptive(2));
  ASSERT_TRUE(plan.ok());
  std::vector<ProbeCommand> commands;
  while (auto c = plan->NextCommand()) commands.push_back(*c);
  ASSERT_EQ(commands.size(), 60u);  // every coarse site; refinement needs fits
  EXPECT_FALSE(plan->IsComplete());
  EXPECT_EQ(plan->Progress().issued, 60);
  for (const auto& c : commands) {
    ASSERT_TRUE(plan->RecordFit(c.sequence, SynthesiseFit(levels.back().limit_positions[c.site.vertex],
                                                          c.site.vertex)).ok());
  }
  EXPECT_GT(plan->Progress().pending, 0);
  EXPECT_TRUE(plan->NextCommand().has_value());
}

TEST(SamplingPlanTest, CommandsCarryTheSiteGeometryAndProbeParameters) {
  const auto levels = TwoMaterialPlate(1);
  SamplingPlanOptions o = Adaptive(1);
  o.probe = {.segment_length_mm = 15.0, .speed_mm_per_s = 8.0, .normal_force_n = 4.0};
  auto plan = SamplingPlan::Create(Pointers(levels), o);
  ASSERT_TRUE(plan.ok());
  std::uint64_t last = 0;
  while (auto c = plan->NextCommand()) {
    EXPECT_GT(c->sequence, last);
    last = c->sequence;
    EXPECT_TRUE(c->position.isApprox(levels.back().limit_positions[c->site.vertex]));
    EXPECT_NEAR(c->normal.z(), 1.0, 1e-12);
    EXPECT_NEAR(c->drag_direction.norm(), 1.0, 1e-12);
    EXPECT_NEAR(c->drag_direction.dot(c->normal), 0.0, 1e-12);
    EXPECT_NEAR(c->drag_direction.x(), 1.0, 1e-12);  // the world axis least aligned with +z: x
    EXPECT_EQ(c->probe.segment_length_mm, 15.0);
    EXPECT_EQ(c->probe.speed_mm_per_s, 8.0);
    EXPECT_EQ(c->probe.normal_force_n, 4.0);
    EXPECT_EQ(c->attempt, 1);
  }
  EXPECT_EQ(last, 60u);
}

TEST(SamplingPlanTest, DeterministicForASeedAndShuffledByIt) {
  const auto levels = TwoMaterialPlate(2);
  auto run = [&](std::uint64_t seed) {
    SamplingPlanOptions o = Adaptive(2);
    o.seed = seed;
    auto plan = SamplingPlan::Create(Pointers(levels), o);
    EXPECT_TRUE(plan.ok());
    return DriveToEnd(*plan, levels.back(), 2);
  };
  const auto a = run(7), b = run(7), c = run(8);
  EXPECT_EQ(a, b);
  ASSERT_EQ(a.size(), c.size());  // the same sites...
  EXPECT_NE(a, c);                // ...in another order
  // Lowest level first: a level-0 site never follows a level-1 site.
  bool seen_level1 = false;
  for (const auto& r : a) {
    if (r.site.level >= 1) seen_level1 = true;
    if (seen_level1) {
      EXPECT_GE(r.site.level, 1);
    }
  }
}

TEST(SamplingPlanTest, RecordingRejectsUnknownDuplicateAndInvalidAnswers) {
  const auto levels = TwoMaterialPlate(1);
  auto plan = SamplingPlan::Create(Pointers(levels), Adaptive(1));
  ASSERT_TRUE(plan.ok());
  auto c = plan->NextCommand();
  ASSERT_TRUE(c.has_value());
  TextureParams bad;
  bad.mu = std::nan("");
  EXPECT_EQ(plan->RecordFit(c->sequence, bad).code(), absl::StatusCode::kInvalidArgument);
  bad.mu = 0.2;
  bad.reflection = {1.2};
  EXPECT_EQ(plan->RecordFit(c->sequence, bad).code(), absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(plan->RecordFit(999, SynthesiseFit(c->position, 0)).code(), absl::StatusCode::kNotFound);
  EXPECT_EQ(plan->RecordFitForSite({0, 12345}, SynthesiseFit(c->position, 0)).code(),
            absl::StatusCode::kFailedPrecondition);
  ASSERT_TRUE(plan->RecordFitForSite(c->site, SynthesiseFit(c->position, c->site.vertex)).ok());
  EXPECT_EQ(plan->RecordFit(c->sequence, SynthesiseFit(c->position, 0)).code(), absl::StatusCode::kNotFound);
  EXPECT_EQ(plan->RecordFailure(c->sequence, "late").code(), absl::StatusCode::kNotFound);
  // An answer to a command superseded by a retry is refused.
  auto d = plan->NextCommand();
  ASSERT_TRUE(plan->RecordFailure(d->sequence, "rig dropped it").ok());
  EXPECT_EQ(plan->RecordFit(d->sequence, SynthesiseFit(d->position, 0)).code(), absl::StatusCode::kNotFound);
}

TEST(SamplingPlanTest, CancelSkipsPendingButAcceptsOutstandingAnswers) {
  const auto levels = TwoMaterialPlate(2);
  auto plan = SamplingPlan::Create(Pointers(levels), Adaptive(2));
  ASSERT_TRUE(plan.ok());
  auto c = plan->NextCommand();
  plan->Cancel();
  EXPECT_FALSE(plan->NextCommand().has_value());
  EXPECT_FALSE(plan->IsComplete());
  ASSERT_TRUE(plan->RecordFit(c->sequence, SynthesiseFit(c->position, c->site.vertex)).ok());
  EXPECT_TRUE(plan->IsComplete());
  const PlanProgress p = plan->Progress();
  EXPECT_EQ(p.measured, 1);
  EXPECT_EQ(p.skipped, 59);
}

TEST(SamplingPlanTest, RejectsInvalidOptionsAndSurfaces) {
  const auto levels = TwoMaterialPlate(2);
  SamplingPlanOptions o = Adaptive(3);  // finer than the surface
  EXPECT_EQ(SamplingPlan::Create(Pointers(levels), o).status().code(), absl::StatusCode::kInvalidArgument);
  o = Adaptive(2);
  o.coarsest_level = 3;
  EXPECT_FALSE(SamplingPlan::Create(Pointers(levels), o).ok());
  o = Adaptive(2);
  o.mode = PlanMode::kUncertainty;  // without a budget
  EXPECT_FALSE(SamplingPlan::Create(Pointers(levels), o).ok());
  o = Adaptive(2);
  o.distance.mu_scale = 0;
  EXPECT_FALSE(SamplingPlan::Create(Pointers(levels), o).ok());
  EXPECT_FALSE(SamplingPlan::Create({}, Adaptive(0)).ok());
  auto broken = levels;
  broken[0].edge_child_vertex.pop_back();
  EXPECT_FALSE(SamplingPlan::Create(Pointers(broken), Adaptive(2)).ok());
}

}  // namespace
}  // namespace surfmap

namespace surfmap {
namespace {

// Progress() keeps counts as sites change state; they must equal a recount
// of the sites at every step, in every mode, through failures, budget skips,
// uncertainty re-selection, cancellation and a save/restore.
PlanProgress RecountProgress(const SamplingPlan& plan) {
  PlanProgress p;
  const SamplingPlanOptions& o = plan.options();
  for (int k = o.coarsest_level; k <= o.max_level; ++k) p.levels.push_back({.level = k});
  for (const SiteRecord& r : plan.Sites()) {
    LevelProgress& l = p.levels[r.site.level - o.coarsest_level];
    int* counts[] = {&l.pending, &l.issued, &l.measured, &l.failed, &l.skipped};
    int* totals[] = {&p.pending, &p.issued, &p.measured, &p.failed, &p.skipped};
    ++*counts[static_cast<int>(r.state)];
    ++*totals[static_cast<int>(r.state)];
  }
  return p;
}

void ExpectCountsMatch(const SamplingPlan& plan, const std::string& when) {
  const PlanProgress kept = plan.Progress();
  const PlanProgress recount = RecountProgress(plan);
  ASSERT_EQ(kept.levels.size(), recount.levels.size()) << when;
  for (size_t k = 0; k < kept.levels.size(); ++k) {
    const LevelProgress& a = kept.levels[k];
    const LevelProgress& b = recount.levels[k];
    ASSERT_TRUE(a.pending == b.pending && a.issued == b.issued && a.measured == b.measured &&
                a.failed == b.failed && a.skipped == b.skipped)
        << when << ": level " << a.level << " kept p/i/m/f/s " << a.pending << "/" << a.issued << "/" << a.measured
        << "/" << a.failed << "/" << a.skipped << " vs recount " << b.pending << "/" << b.issued << "/"
        << b.measured << "/" << b.failed << "/" << b.skipped;
  }
  ASSERT_EQ(kept.measured, recount.measured) << when;
  ASSERT_EQ(kept.skipped, recount.skipped) << when;
}

class ProgressCountTest : public ::testing::TestWithParam<PlanMode> {};

TEST_P(ProgressCountTest, KeptCountsEqualARecountAtEveryStep) {
  const auto levels = testing::TwoMaterialPlate(3);
  SamplingPlanOptions options;
  options.mode = GetParam();
  options.max_level = 3;
  options.threshold = 1.0;
  options.seed = 5;
  options.sample_budget = 70;  // reached: pending sites get skipped
  options.max_retries = 1;
  absl::StatusOr<SamplingPlan> plan = SamplingPlan::Create(testing::Pointers(levels), options);
  ASSERT_TRUE(plan.ok()) << plan.status();
  std::deque<ProbeCommand> outstanding;
  int step = 0;
  while (true) {
    while (std::optional<ProbeCommand> c = plan->NextCommand()) outstanding.push_back(*c);
    ExpectCountsMatch(*plan, "after issuing, step " + std::to_string(step));
    if (outstanding.empty()) break;
    const ProbeCommand c = outstanding.front();
    outstanding.pop_front();
    absl::Status s = step % 5 == 2 ? plan->RecordFailure(c.sequence, "slipped")
                                   : plan->RecordFit(c.sequence, testing::SynthesiseFit(
                                                                     levels.back().limit_positions[c.site.vertex],
                                                                     c.site.vertex));
    ASSERT_TRUE(s.ok()) << s;
    ExpectCountsMatch(*plan, "after answer " + std::to_string(step));
    if (step == 40) {
      absl::StatusOr<SamplingPlan> restored = SamplingPlan::Restore(plan->SaveJson(), testing::Pointers(levels));
      ASSERT_TRUE(restored.ok()) << restored.status();
      ExpectCountsMatch(*restored, "restored");
    }
    ++step;
  }
  EXPECT_GT(plan->Progress().skipped + plan->Progress().failed, 0);
  plan->Cancel();
  ExpectCountsMatch(*plan, "cancelled");
}

INSTANTIATE_TEST_SUITE_P(Modes, ProgressCountTest,
                         ::testing::Values(PlanMode::kAdaptive, PlanMode::kUncertainty, PlanMode::kUniform),
                         [](const auto& info) { return std::string(PlanModeName(info.param)); });

}  // namespace
}  // namespace surfmap

namespace surfmap {
namespace {

// A measured drag along `direction`: a straight 16 mm data window (the
// middle 80 % of a 20 mm drag) through the site, one piece.
LineSample StraightDrag(const ProbeCommand& c, const Eigen::Vector3d& direction, const TextureParams& fit) {
  LineSample line;
  for (int k = 0; k <= 16; ++k) {
    line.path_s_mm.push_back(k);
    line.path_points.push_back(c.position + (k - 8.0) * direction);
  }
  LinePiece piece;
  piece.start_mm = 0.0;
  piece.end_mm = 16.0;
  piece.texture = fit;
  piece.effective_pairs = 100.0;
  piece.mu_se = fit.mu_std / 10.0;
  line.pieces.push_back(piece);
  return line;
}

// The coarsest-level sites still pending after the first drag is measured,
// and those skipped as covered by it.
// With `change`, the drag found a change half-way along (two pieces), and
// only `share` applies; without, `quiet_share` does too.
void FirstDragSkips(double share, std::set<int>* skipped, std::set<int>* expected, double quiet_share = 0.0,
                    bool change = false) {
  const auto levels = TwoMaterialPlate(1);
  SamplingPlanOptions o;
  o.mode = PlanMode::kBoundary;
  o.max_level = 1;
  o.coverage_skip_share = share;
  o.quiet_coverage_skip_share = quiet_share;
  auto plan = SamplingPlan::Create(Pointers(levels), o);
  ASSERT_TRUE(plan.ok()) << plan.status();
  const std::optional<ProbeCommand> c = plan->NextCommand();
  ASSERT_TRUE(c.has_value());
  // Dragged towards the nearest other coarse site (11.1 mm on the plate), so
  // its window ends 3.1 mm short of it.
  int nearest = -1;
  for (const SiteRecord& r : plan->Sites()) {
    if (r.site.vertex == c->site.vertex) continue;
    const double d = (levels[1].limit_positions[r.site.vertex] - c->position).norm();
    if (nearest < 0 || d < (levels[1].limit_positions[nearest] - c->position).norm()) nearest = r.site.vertex;
  }
  ASSERT_GE(nearest, 0);
  const Eigen::Vector3d direction = (levels[1].limit_positions[nearest] - c->position).normalized();
  LineSample line = StraightDrag(*c, direction, SynthesiseFit(c->position, c->site.vertex));
  if (change) {
    LinePiece second = line.pieces[0];
    line.pieces[0].end_mm = second.start_mm = 8.0;
    second.texture.mu += 0.2;
    line.pieces.push_back(second);
  }
  const double reach = change ? share : std::max(share, quiet_share);
  // Expected from the geometry: within reach x 20 mm of the 16 mm window.
  const Eigen::Vector3d a = line.path_points.front(), b = line.path_points.back();
  for (const SiteRecord& r : plan->Sites()) {
    if (r.state != SiteState::kPending) continue;
    const Eigen::Vector3d p = levels[1].limit_positions[r.site.vertex];
    const double t = std::clamp((p - a).dot(b - a) / (b - a).squaredNorm(), 0.0, 1.0);
    if ((p - (a + t * (b - a))).norm() <= reach * o.probe.segment_length_mm) expected->insert(r.site.vertex);
  }
  ASSERT_TRUE(plan->RecordLineSample(c->sequence, line).ok());
  for (const SiteRecord& r : plan->Sites()) {
    if (r.state != SiteState::kSkipped) continue;
    skipped->insert(r.site.vertex);
    EXPECT_EQ(r.reason, absl::StrCat("covered by the drag at vertex ", c->site.vertex));
  }
}

TEST(CoverageSkip, ACoarseSiteAMeasuredDragPassedNearIsSkippedAsCovered) {
  std::set<int> skipped, expected;
  FirstDragSkips(0.25, &skipped, &expected);
  // The drag's window ends 3.1 mm from the nearest site: within 5 mm.
  EXPECT_FALSE(expected.empty());
  EXPECT_EQ(skipped, expected);
}

TEST(CoverageSkip, ADragThatFoundNoChangeCoversFartherThanOneThatCrossedABoundary) {
  std::set<int> quiet, quiet_expected, crossed, crossed_expected, near, near_expected;
  // A whole drag length for the quiet one: the plate's coarse sites lie
  // 11.1 mm apart, so 5 and 10 mm of the window reach the same two.
  FirstDragSkips(0.25, &quiet, &quiet_expected, 1.0, /*change=*/false);
  FirstDragSkips(0.25, &crossed, &crossed_expected, 1.0, /*change=*/true);
  FirstDragSkips(0.25, &near, &near_expected);
  EXPECT_EQ(quiet, quiet_expected);
  EXPECT_EQ(crossed, crossed_expected);
  // The quiet drag skips more than the corridor's share; the one that
  // crossed a boundary only that.
  EXPECT_GT(quiet.size(), near.size());
  EXPECT_EQ(crossed, near);
}

TEST(CoverageSkip, ShareZeroDragsEveryCoarseSite) {
  std::set<int> skipped, expected;
  FirstDragSkips(0.0, &skipped, &expected);
  EXPECT_TRUE(skipped.empty());
}

// The boundary plan's pending selected sites: vertex -> selection rank.
std::map<int, int> PendingSelected(const SamplingPlan& plan) {
  std::map<int, int> out;
  for (const SiteRecord& r : plan.Sites()) {
    if (r.state == SiteState::kPending && r.origin == SiteOrigin::kSelected) out[r.site.vertex] = r.selection_rank;
  }
  return out;
}

// Answers one rig with the truth's fits until the boundary plan has chosen
// sites (the coarse pass is done).
void AnswerUntilSelection(SamplingPlan& plan, const SurfaceLevel& finest) {
  while (PendingSelected(plan).empty() && !plan.IsComplete()) {
    const std::optional<ProbeCommand> c = plan.NextCommand();
    ASSERT_TRUE(c.has_value());
    ASSERT_TRUE(plan.RecordFit(c->sequence, SynthesiseFit(finest.limit_positions[c->site.vertex], c->site.vertex)).ok());
  }
}

// Over `answers` answers after the coarse pass, how many commands issued a
// selected site that was not its selection's first choice.
int LaterChoicesIssuedFirst(bool by_gain, int answers, std::string* saved = nullptr) {
  const auto levels = TwoMaterialPlate(3);
  SamplingPlanOptions o;
  o.mode = PlanMode::kBoundary;
  o.max_level = 3;
  o.seed = 17;
  o.issue_selected_by_gain = by_gain;
  auto plan = SamplingPlan::Create(Pointers(levels), o);
  EXPECT_TRUE(plan.ok()) << plan.status();
  if (!plan.ok()) return -1;
  AnswerUntilSelection(*plan, levels.back());
  int later = 0;
  for (int k = 0; k < answers && !plan->IsComplete(); ++k) {
    const std::map<int, int> selected = PendingSelected(*plan);
    EXPECT_FALSE(selected.empty());
    std::set<int> ranks;
    for (const auto& [v, rank] : selected) ranks.insert(rank);
    EXPECT_EQ(*ranks.begin(), 1);
    EXPECT_EQ(*ranks.rbegin(), static_cast<int>(selected.size())) << "ranks are 1..n, each once";
    EXPECT_EQ(ranks.size(), selected.size());
    if (k == answers / 2 && saved != nullptr) *saved = plan->SaveJson();
    const std::optional<ProbeCommand> c = plan->NextCommand();
    EXPECT_TRUE(c.has_value());
    if (!c) return -1;
    auto it = selected.find(c->site.vertex);
    EXPECT_NE(it, selected.end()) << "after the coarse pass every command is a selected site";
    later += it != selected.end() && it->second != 1;
    EXPECT_TRUE(plan->RecordFit(c->sequence, SynthesiseFit(levels.back().limit_positions[c->site.vertex],
                                                             c->site.vertex)).ok());
  }
  return later;
}

TEST(IssueOrder, ByGainASelectionIsIssuedInTheOrderItsSitesWereChosen) {
  EXPECT_EQ(LaterChoicesIssuedFirst(/*by_gain=*/true, 24), 0);
  // The plan's issue order (level, then the seeded shuffle) issued later
  // choices first: the build before.
  EXPECT_GT(LaterChoicesIssuedFirst(/*by_gain=*/false, 24), 0);
}

TEST(IssueOrder, ARestoredPlanKeepsItsSelectionsOrder) {
  std::string saved;
  ASSERT_EQ(LaterChoicesIssuedFirst(/*by_gain=*/true, 24, &saved), 0);
  ASSERT_FALSE(saved.empty());
  const auto levels = TwoMaterialPlate(3);
  auto live = SamplingPlan::Restore(saved, Pointers(levels));
  ASSERT_TRUE(live.ok()) << live.status();
  const std::map<int, int> selected = PendingSelected(*live);
  ASSERT_GT(selected.size(), 1u);
  auto restored = SamplingPlan::Restore(live->SaveJson(), Pointers(levels));
  ASSERT_TRUE(restored.ok()) << restored.status();
  EXPECT_EQ(PendingSelected(*restored), selected);
  const std::optional<ProbeCommand> c = restored->NextCommand();
  ASSERT_TRUE(c.has_value());
  EXPECT_EQ(selected.at(c->site.vertex), 1);
}

}  // namespace
}  // namespace surfmap
