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

// Everything the request does not name keeps SamplingPlanOptions' default.
SamplingPlanOptions PlanOptionsFor(const PlanRequest& request);

}  // namespace surfmap
