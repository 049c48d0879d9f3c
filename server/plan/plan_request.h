// What a mapping run asks of its sampling plan, and the plan's options for
// it: the one place a request becomes SamplingPlanOptions. A job
// (server/jobs PlanOptionsFor) and an in-process run (clients/mapsim) both
// build their plans here, so surfmap-mapsim plans exactly as the service does
// and a default added to the plan reaches both.
#pragma once

#include <cstdint>

#include "server/estimate/texture.h"
#include "server/plan/probe_command.h"
#include "server/plan/reachability.h"
#include "server/plan/sampling_plan_options.h"

namespace surfmap {

// SamplingPlanOptions' defaults: the one set PlanRequest's are read from.
inline const SamplingPlanOptions& DefaultPlanOptions() {
  static const SamplingPlanOptions defaults;
  return defaults;
}

// A request that names nothing plans as SamplingPlanOptions{} does: every
// default is read from it (it once had its own, which disagreed in mode,
// finest level and property; plan_request_test checks every field).
struct PlanRequest {
  PlanMode mode = DefaultPlanOptions().mode;
  int coarsest_level = DefaultPlanOptions().coarsest_level;
  int finest_level = DefaultPlanOptions().max_level;  // the plan's max level
  double threshold = DefaultPlanOptions().threshold;  // kAdaptive, in TextureDistance units
  // What the texture distance compares.
  TextureProperty property = DefaultPlanOptions().distance.property;
  int budget = DefaultPlanOptions().sample_budget;  // max samples; 0 = the mode's default
  int max_retries = DefaultPlanOptions().max_retries;
  ProbeParameters probe = DefaultPlanOptions().probe;  // the paper's drag
  std::uint64_t seed = DefaultPlanOptions().seed;
  Reachability reach = DefaultPlanOptions().reach;  // sites outside are not planned
};

// BOUNDARY's default site spacing as a share of the drag length. Its budget
// is 1.5 drags per level-0 site, so on a scan the server simplifies, the
// spacing sets how many drags the object gets. A drag apart (the other
// modes' default), two scan-like held-out objects (clients/sim/scenes
// scan_pebble_m, scan_vase_m) lost whole drag-sized features on half their
// seeds (worst region 34 % mean); the bundled scenes, on which the method was
// developed, have hand-made control meshes 13-20 mm apart (sqrt(area /
// vertices) for 20 mm drags), and 0.65 puts a scan at the dense end of that
// range (docs/method.md, "A scan's site spacing").
inline constexpr double kBoundarySiteSpacingShare = 0.65;

// The spacing a job gets when its spec leaves it at 0: the drag length for
// UNIFORM, ADAPTIVE and UNCERTAINTY (each site is dragged once, a drag
// apart), kBoundarySiteSpacingShare of it for BOUNDARY.
double DefaultSiteSpacingMm(PlanMode mode, double drag_length_mm);

// Everything the request does not name keeps SamplingPlanOptions' default.
SamplingPlanOptions PlanOptionsFor(const PlanRequest& request);

}  // namespace surfmap
