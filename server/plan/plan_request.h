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

struct PlanRequest {
  PlanMode mode = PlanMode::kBoundary;
  int coarsest_level = 0;
  int finest_level = 3;          // the plan's max level
  double threshold = 1.0;        // kAdaptive, in TextureDistance units
  TextureProperty property = TextureProperty::kFriction;  // what the texture distance compares
  int budget = 0;                // max samples; 0 = the mode's default
  int max_retries = 2;
  ProbeParameters probe;         // the paper's drag by default
  std::uint64_t seed = 1;
  Reachability reach;            // sites outside are not planned
};

// Everything the request does not name keeps SamplingPlanOptions' default.
SamplingPlanOptions PlanOptionsFor(const PlanRequest& request);

}  // namespace surfmap
