// What a job will cost before it runs: the plan's size and the robot time at
// the job's probe settings, and whether the probe settings suit the object.
//
// Time model (documented in the README): each drag takes
//   approach_s (move to the site, descend, settle the normal force, lift off;
//   kApproachSeconds by default, a typical arm at cautious speeds)
//   + 2 x segment / speed (forward and reverse pass) + kPauseSeconds
// and drags run one after another on one rig.
#pragma once

#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "server/jobs/job_params.h"
#include "server/mesh/loop_surface.h"

namespace surfmap {

inline constexpr double kApproachSeconds = 3.0;
inline constexpr double kPauseSeconds = 0.5;  // the simulator's and the paper's pause between passes
// Adaptive jobs refine where neighbouring sites differ: on the bottle (82
// control vertices, three patches, threshold 4) 100 sites in all, 1.22x. A
// rule of thumb, not a bound: an object with many boundaries needs more.
inline constexpr double kAdaptiveRefinementFactor = 1.25;

// Level-0 sites closer than this fraction of the drag warn: at the default
// spacing (the drag length) a simplified mesh's mean edge comes out 0.8-1.1 x
// the spacing, which must not warn; half a drag apart, each drag runs over
// its neighbours' sites.
inline constexpr double kOverlapFraction = 0.75;

struct PlanEstimate {
  int level0_sites = 0;     // vertices of the coarsest level: every mode measures them first
  int expected_sites = 0;
  int max_sites = 0;        // budget, or every vertex the plan may reach
  double control_spacing_mm = 0;  // mean edge length of the coarsest level (on the surface)
  int control_vertices = 0;       // of level 0
  double seconds_per_drag = 0;
  double level0_seconds = 0;
  double expected_seconds = 0;
  double approach_s = kApproachSeconds;
  double largest_extent_mm = 0;
  std::vector<std::string> warnings;
};

// FAILED_PRECONDITION when the drag is longer than the object's largest
// extent (it cannot fit on it). Warnings: a drag longer than half the
// object's largest extent; level-0 sites closer together than kOverlapFraction
// of the drag (their drags overlap; not for BOUNDARY, whose default spacing is
// closer).
absl::StatusOr<PlanEstimate> EstimatePlan(const JobParams& params, const LoopSurface& surface);

}  // namespace surfmap
