#include "server/plan/plan_request.h"

namespace surfmap {

SamplingPlanOptions PlanOptionsFor(const PlanRequest& r) {
  SamplingPlanOptions o;
  o.mode = r.mode;
  o.coarsest_level = r.coarsest_level;
  o.max_level = r.finest_level;
  o.threshold = r.threshold;
  o.distance.property = r.property;
  o.sample_budget = r.budget;
  o.max_retries = r.max_retries;
  o.probe = r.probe;
  o.seed = r.seed;
  o.reach = r.reach;
  return o;
}

double DefaultSiteSpacingMm(PlanMode mode, double drag_length_mm) {
  return mode == PlanMode::kBoundary ? kBoundarySiteSpacingShare * drag_length_mm : drag_length_mm;
}

}  // namespace surfmap
