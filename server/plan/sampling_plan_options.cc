#include "server/plan/sampling_plan_options.h"

#include <cmath>

#include "absl/strings/str_cat.h"

namespace surfmap {

bool SamplingPlanOptions::IsValid(std::string* why) const {
  auto fail = [why](std::string msg) {
    if (why) *why = std::move(msg);
    return false;
  };
  auto positive = [](double x) { return std::isfinite(x) && x > 0; };
  if (coarsest_level < 0) return fail(absl::StrCat("coarsest_level must be >= 0, got ", coarsest_level));
  if (max_level < coarsest_level) {
    return fail(absl::StrCat("max_level (", max_level, ") must be >= coarsest_level (", coarsest_level, ")"));
  }
  if (!std::isfinite(threshold) || threshold < 0) return fail(absl::StrCat("threshold must be >= 0, got ", threshold));
  if (std::string distance_why; !distance.IsValid(&distance_why)) return fail(absl::StrCat("distance: ", distance_why));
  if (sample_budget < 0) return fail(absl::StrCat("sample_budget must be >= 0, got ", sample_budget));
  if (mode == PlanMode::kUncertainty && sample_budget == 0) {
    return fail("uncertainty mode needs a sample_budget > 0 (it would otherwise sample every vertex)");
  }
  if (max_retries < 0) return fail(absl::StrCat("max_retries must be >= 0, got ", max_retries));
  if (!positive(probe.segment_length_mm)) return fail("probe segment_length_mm must be > 0");
  if (!positive(probe.speed_mm_per_s)) return fail("probe speed_mm_per_s must be > 0");
  if (!positive(probe.normal_force_n)) return fail("probe normal_force_n must be > 0");
  if (!std::isfinite(gradient_weight) || gradient_weight < 0) return fail("gradient_weight must be >= 0");
  if (!std::isfinite(min_uncertainty_score) || min_uncertainty_score < 0) {
    return fail("min_uncertainty_score must be >= 0");
  }
  std::string map_why;
  if (!map.IsValid(&map_why)) return fail(absl::StrCat("map: ", map_why));
  if (!reach.IsValid(&map_why)) return fail(absl::StrCat("reach: ", map_why));
  if (!regions.IsValid(&map_why)) return fail(absl::StrCat("regions: ", map_why));
  if (!(continuation_prior >= 0.0 && continuation_prior <= 1.0)) {
    return fail(absl::StrCat("continuation_prior must be in [0, 1], got ", continuation_prior));
  }
  if (!(misclassification_cost >= 0.0 && std::isfinite(misclassification_cost))) {
    return fail(absl::StrCat("misclassification_cost must be finite and >= 0, got ", misclassification_cost));
  }
  if (!(small_material_weight_max >= 1.0 && std::isfinite(small_material_weight_max))) {
    return fail(absl::StrCat("small_material_weight_max must be finite and >= 1, got ", small_material_weight_max));
  }
  if (!(coverage_skip_share >= 0.0 && coverage_skip_share <= 1.0)) {
    return fail(absl::StrCat("coverage_skip_share must be in [0, 1], got ", coverage_skip_share));
  }
  if (!(quiet_coverage_skip_share >= 0.0 && quiet_coverage_skip_share <= 1.0)) {
    return fail(absl::StrCat("quiet_coverage_skip_share must be in [0, 1], got ", quiet_coverage_skip_share));
  }
  if (lookahead < 1) return fail(absl::StrCat("lookahead must be >= 1, got ", lookahead));
  return true;
}

std::string_view PlanModeName(PlanMode mode) {
  switch (mode) {
    case PlanMode::kAdaptive:
      return "adaptive";
    case PlanMode::kUniform:
      return "uniform";
    case PlanMode::kUncertainty:
      return "uncertainty";
    case PlanMode::kBoundary:
      return "boundary";
  }
  return "adaptive";
}

std::optional<PlanMode> ParsePlanMode(std::string_view name) {
  for (PlanMode m : {PlanMode::kAdaptive, PlanMode::kUniform, PlanMode::kUncertainty, PlanMode::kBoundary}) {
    if (PlanModeName(m) == name) return m;
  }
  return std::nullopt;
}

}  // namespace surfmap
