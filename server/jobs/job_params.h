// What a mapping job was asked to do: the domain form of the API's JobSpec,
// stored as the job's params_json so a restarted server rebuilds the job.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>
#include "absl/status/statusor.h"
#include "server/estimate/fit_trace.h"
#include "server/estimate/texture.h"
#include "server/plan/plan_request.h"
#include "server/plan/probe_command.h"
#include "server/jobs/trace_plausibility.h"
#include "server/plan/reachability.h"
#include "server/plan/sampling_plan_options.h"
#include "server/mesh/loop_surface.h"

namespace surfmap {

// finest_level / map_level before CreateJob resolves them: chosen from the
// object's control mesh (ResolveAutoLevels).
inline constexpr int kAutoLevel = -1;

struct JobParams {
  int64_t object_id = 0;
  TextureProperty property = TextureProperty::kFriction;
  PlanMode mode = PlanMode::kBoundary;
  int coarsest_level = 0;
  int finest_level = 3;          // the plan's finest level
  // The level the map is evaluated on (>= finest_level): boundaries are
  // resolved below a drag's precision there, independent of the levels
  // sampled. Parameters stored before it existed read as finest_level.
  int map_level = 3;
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
  // existed, and in-process callers). The API's default: DefaultSiteSpacingMm.
  double site_spacing_mm = 0;
  Reachability reach;            // sites a rig cannot reach are not planned

  // Names the first invalid field. kAutoLevel levels are invalid here:
  // resolve them first.
  bool IsValid(std::string* why) const;
};

// Replaces kAutoLevel levels: map_level by MapLevelFor (edges of ~1 mm on
// the object's control mesh, level 0 of `surface`), finest_level
// kPlanLevelsBelowMap coarser (~4 mm edges: enough to decide where to drag,
// at a sixteenth of the map's cost to rebuild the plan's own map after every
// drag), never below
// coarsest_level; a given finest_level finer than the auto map level raises
// map_level to it.
void ResolveAutoLevels(const SurfaceLevel& control_level, JobParams& params);

// The levels a job's plan runs on: 0..finest_level of `surface`, which is
// refined to map_level.
std::vector<const SurfaceLevel*> JobPlanLevels(const LoopSurface& surface, const JobParams& params);

nlohmann::json JobParamsToJson(const JobParams& params);
nlohmann::json TraceLimitsToJson(const TraceLimits& limits);
absl::StatusOr<TraceLimits> TraceLimitsFromJson(const nlohmann::json& json);
// What the job asks of its plan, and the plan's options for it (through
// server/plan's PlanOptionsFor(PlanRequest), as surfmap-mapsim's runs).
PlanRequest PlanRequestOf(const JobParams& params);
SamplingPlanOptions PlanOptionsFor(const JobParams& params);
absl::StatusOr<JobParams> JobParamsFromJson(const nlohmann::json& json);

}  // namespace surfmap
