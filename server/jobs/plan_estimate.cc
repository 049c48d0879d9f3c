#include "server/jobs/plan_estimate.h"

#include <algorithm>
#include <cmath>

#include "absl/strings/str_format.h"
#include "server/plan/sampling_plan.h"

namespace surfmap {

absl::StatusOr<PlanEstimate> EstimatePlan(const JobParams& params, const LoopSurface& surface) {
  PlanEstimate e;
  const SurfaceLevel& coarse = surface.level(params.coarsest_level);
  const SurfaceLevel& finest = surface.level(params.finest_level);
  e.level0_sites = static_cast<int>(coarse.limit_positions.size());
  e.control_vertices = static_cast<int>(surface.level(0).limit_positions.size());
  const int finest_vertices = static_cast<int>(finest.limit_positions.size());

  double edge_sum = 0;
  for (const auto& edge : coarse.edges) {
    edge_sum += (coarse.limit_positions[edge[1]] - coarse.limit_positions[edge[0]]).norm();
  }
  e.control_spacing_mm = coarse.edges.empty() ? 0 : edge_sum / static_cast<double>(coarse.edges.size());

  Eigen::Vector3d lo = Eigen::Vector3d::Constant(INFINITY), hi = Eigen::Vector3d::Constant(-INFINITY);
  for (const Eigen::Vector3d& p : finest.limit_positions) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  e.largest_extent_mm = finest.limit_positions.empty() ? 0 : (hi - lo).maxCoeff();

  const int budget = params.budget > 0 ? params.budget : 0;
  switch (params.mode) {
    case PlanMode::kUniform:
      e.max_sites = e.level0_sites;
      e.expected_sites = e.level0_sites;
      break;
    case PlanMode::kAdaptive:
      e.max_sites = finest_vertices;
      e.expected_sites = static_cast<int>(std::lround(e.level0_sites * kAdaptiveRefinementFactor));
      break;
    case PlanMode::kUncertainty:
      e.max_sites = finest_vertices;
      e.expected_sites = budget > 0 ? budget : finest_vertices;
      break;
    case PlanMode::kBoundary: {
      const int default_budget = DefaultSampleBudget(JobPlanLevels(surface, params));
      e.max_sites = default_budget > 0 ? default_budget : finest_vertices;
      e.expected_sites = e.max_sites;
      break;
    }
  }
  if (budget > 0) {
    e.max_sites = std::min(e.max_sites, budget);
    e.expected_sites = std::min(e.expected_sites, budget);
  }
  e.expected_sites = std::min(std::max(e.expected_sites, std::min(e.level0_sites, e.max_sites)), e.max_sites);

  const ProbeParameters& probe = params.probe;
  e.seconds_per_drag = e.approach_s + 2.0 * probe.segment_length_mm / probe.speed_mm_per_s + kPauseSeconds;
  e.level0_seconds = e.seconds_per_drag * std::min(e.level0_sites, e.max_sites);
  e.expected_seconds = e.seconds_per_drag * e.expected_sites;

  const double drag = probe.segment_length_mm;
  if (drag > e.largest_extent_mm) {
    return absl::FailedPreconditionError(absl::StrFormat(
        "the drag (%g mm) is longer than the object (largest extent %.3g mm): it cannot fit on the surface; "
        "use a shorter probe.segment_length_mm, or check the object's units",
        drag, e.largest_extent_mm));
  }
  if (drag > 0.5 * e.largest_extent_mm) {
    e.warnings.push_back(absl::StrFormat(
        "the drag (%g mm) is long against the object (largest extent %.3g mm): most drags will run off edges "
        "or around curves; a drag under half the object is advised",
        drag, e.largest_extent_mm));
  }
  // BOUNDARY's drags overlap on purpose (its default spacing is 0.65 of the
  // drag; its coverage skip drops a site a measured drag passed near).
  if (params.mode != PlanMode::kBoundary && e.control_spacing_mm > 0 && e.control_spacing_mm < kOverlapFraction * drag) {
    e.warnings.push_back(absl::StrFormat(
        "level-%d sites are %.3g mm apart on average, closer than 3/4 of the drag (%g mm): neighbouring drags "
        "overlap; "
        "raise site_spacing_mm (or shorten the drag) to measure each patch once",
        params.coarsest_level, e.control_spacing_mm, drag));
  }
  return e;
}

}  // namespace surfmap
