// What a mapping job was asked to do: the domain form of the API's JobSpec,
// stored as the job's params_json so a restarted server rebuilds the job.
#pragma once

#include <cstdint>
#include <string>

#include <nlohmann/json.hpp>
#include "absl/status/statusor.h"
#include "server/estimate/fit_trace.h"
#include "server/estimate/texture.h"
#include "server/plan/probe_command.h"
#include "server/jobs/trace_plausibility.h"
#include "server/plan/sampling_plan_options.h"

namespace surfmap {

struct JobParams {
  int64_t object_id = 0;
  TextureProperty property = TextureProperty::kFriction;
  PlanMode mode = PlanMode::kAdaptive;
  int coarsest_level = 0;
  int finest_level = 3;
  double threshold = 1.0;        // texture distance (see texture.h for its scale)
  int budget = 0;                // max samples; 0 = unlimited
  ProbeParameters probe;          // the paper's drag by default
  uint64_t seed = 1;
  int max_retries = 2;
  int64_t lease_ms = 60'000;
  FitOptions fit;                // estimator settings for fits on arrival
  TraceLimits limits;            // plausibility of submitted traces
  // Target distance between level-0 sites (SurfaceCache simplifies a denser
  // mesh to it); 0 = the object's mesh as it is (jobs stored before spacing
  // existed, and in-process callers). The API's default is the drag length.
  double site_spacing_mm = 0;

  // Names the first invalid field.
  bool IsValid(std::string* why) const;
};

nlohmann::json JobParamsToJson(const JobParams& params);
nlohmann::json TraceLimitsToJson(const TraceLimits& limits);
absl::StatusOr<TraceLimits> TraceLimitsFromJson(const nlohmann::json& json);
// The sampling plan's options for these job parameters.
SamplingPlanOptions PlanOptionsFor(const JobParams& params);
absl::StatusOr<JobParams> JobParamsFromJson(const nlohmann::json& json);

}  // namespace surfmap
