// Options of a sampling plan (see sampling_plan.h).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "server/estimate/texture.h"
#include "server/map/friction_map.h"
#include "server/map/region_map.h"
#include "server/plan/probe_command.h"
#include "server/plan/reachability.h"

namespace surfmap {

enum class PlanMode {
  // The paper's rule: measure every vertex of `coarsest_level`; refine an edge
  // of level k < max_level whose ends differ by more than `threshold`.
  kAdaptive,
  // Every vertex of `coarsest_level` and nothing else (a baseline: set
  // coarsest_level to the level to compare against).
  kUniform,
  // Every vertex of `coarsest_level` first, then one site at a time wherever
  // the interpolated map (server/map) is most uncertain, weighted by its local
  // value gradient, among the vertices of levels coarsest..max_level not yet
  // sampled. Needs a sample budget.
  kUncertainty,
  // Goes looking for boundaries (beyond the paper): every vertex of
  // `coarsest_level` first, dragged in orientations that vary from site to
  // site (nothing is known yet); then, a few at a time, the vertex of
  // max_level where one more drag would remove the most squared map error:
  // the map's variance (region_map.h: boundaries between regions that differ
  // beyond their measurement uncertainty, and distance from data) summed over
  // the drag's reach. Each such drag is turned to cross the boundary it was
  // placed for. The regions come from the pieces of the drags, so a drag that
  // found a change inside it marks a boundary at once. Its default budget
  // (sample_budget 0) is DefaultSampleBudget.
  kBoundary,
};

// The plan's own region map: RegionMapOptions without the split against
// the materials' textures, the texture assignment, the dissolving of
// mixtures (measured on the served map only), the chains carried on,
// the links longer than a drag, the lines, dots, rectangles, cut and sharp corners, the spreads' floor, the end pieces' marks, and the materials' mu from long pieces (each measured on the served map
// over the plan's drags, docs/method.md section 5).
inline RegionMapOptions PlanRegionMapOptions() {
  RegionMapOptions options;
  options.split_against_materials = false;
  options.assign_by_texture = false;
  options.dissolve_mixture_materials = false;
  options.move_only_to_alike_material = false;  // the plan issues the drags it issued before the rule
  options.links.max_extension_turn_deg = 0.0;
  options.links.max_line_turn_deg = 0.0;
  options.links.max_dot_radius_mm = 0.0;
  options.links.max_rectangle_side_mm = 0.0;  // the plan issues the drags it issued before rectangles
  options.links.max_corner_side_residual_mm = 0.0;
  options.links.chain_ends_reach_past_short_links = false;  // the plan issues the drags it issued before
  options.links.max_bridge_mm = 0.0;  // the plan issues the drags it issued before bridges
  options.merge.spread_floor = 0.0;
  options.min_end_piece_mark_mm = 0.0;
  options.boundaries_ignore_unconfirmed_end_pieces = false;  // none without the marks' rule; and no copy of the data
  options.transition_pieces_mark_one_crossing = false;  // none without the marks' rule either
  options.min_fitted_pieces_for_mu = 0;
  options.link_materials = false;
  options.links.max_length_mm = 20.0;  // a drag length: the served map's 25 mm measured on the same drags only
  options.links.corner_reach_mm = 20.0;  // the link's: the served map's 25 mm measured on the same drags only
  options.links.max_corner_turn_deg = 120.0;  // the served map's 155 measured on the same drags only
  options.links.max_curve_turn_deg = 0.0;  // chords: the plan issues the drags it issued before curves
  options.links.min_crossing_cos = 0.866;  // cos 30 degrees: the served map's 32 measured on the same drags only
  return options;
}

struct SamplingPlanOptions {
  PlanMode mode = PlanMode::kAdaptive;
  int coarsest_level = 0;
  int max_level = 2;          // the finest level refinement may reach (<= the surface's)
  double threshold = 1.0;     // kAdaptive: refine where TextureDistance(ends) > threshold
  TextureDistanceOptions distance;
  // At most this many sites measured + issued; 0 = unlimited (not allowed for
  // kUncertainty; DefaultSampleBudget for kBoundary). Failed and skipped
  // sites do not count.
  int sample_budget = 0;
  int max_retries = 2;        // a failed site is re-queued this many times, then fails for good
  ProbeParameters probe;
  std::uint64_t seed = 1;     // issue order among sites of one level (site_order.h)
  // kUncertainty: score = mu_std * (1 + gradient_weight * g * d / s), with the
  // map's mu_std, local gradient g, distance d to the nearest sample or issued
  // site, and prior std s (friction_map.h). g * d ~ the jump across a gap
  // between differing samples, whatever its width: gaps across a boundary
  // are split breadth-first. Stop when the best score falls below
  // min_uncertainty_score.
  double gradient_weight = 1.0;
  double min_uncertainty_score = 0.0;
  FrictionMapOptions map;     // kUncertainty: the map that scores candidate sites

  // Sites a rig cannot reach are skipped (with the reason) instead of planned.
  Reachability reach;
  // kBoundary: the map that scores candidate sites and orients the drags.
  // It does not split pieces against its materials' textures (the served map
  // does): it is rebuilt after every drag and the split groups its pieces twice, and
  // measured through the service over six seeds a plan that split chose other
  // drags for no gain beyond the plans' own chaos (docs/method.md). So the
  // plan issues the drags it issued before the split existed.
  RegionMapOptions regions = PlanRegionMapOptions();
  // kBoundary: at most this many selected sites outstanding at once. Each
  // is chosen with the others counted as covered; more rigs than this wait
  // rather than measure where the newest drags would have sent them.
  int lookahead = 4;
  // kBoundary: follow every boundary a drag crossed, a drag at a time along
  // it, before choosing by uncertainty (boundary_tracing.h). Off by default:
  // measured over six seeds it keeps narrow bands whole but starves
  // drag-sized patches of the follow-up budget (docs/method.md section 5).
  bool follow_boundaries = false;
  // kBoundary: a boundary a drag crossed may go on past the crossing where no
  // other crossing of it is near (boundary_tracing.h). With a prior p > 0, a
  // drag across where it would be if it went on straight competes with the
  // map's choices with an extra gain of p times the error the map holds
  // there under that hypothesis (ContinuationError): where data of one
  // region on both sides pinched a narrow band off, the map is confident and
  // wrong, and its own uncertainty sends no drag back. Off by default:
  // measured over six seeds of seven scenes (docs/method.md section 5) it
  // keeps the banded vase's band whole more often but takes the budget that
  // small patches and the other scenes' boundaries needed. Plans stored
  // without the key restore with 0.
  double continuation_prior = 0.0;
  // kBoundary: the map's errors are measured in the job's property
  // (distance.property): a friction job weighs a boundary by its mu jump
  // squared, a roughness or both job by its texture distance (friction and
  // roughness, in mu^2), and the far-from-data term by the pieces' spread in
  // that metric (boundary_selection.h). False: always by friction, the
  // build before. Plans stored without the key restore with false.
  bool boundary_cost_follows_property = true;
  // kBoundary: what a point the map gives the wrong material costs, mu^2, on
  // top of its squared error (boundary_selection.h), so that a boundary of
  // low contrast is not starved. The issue's goals price it: an RMSE of 0.03
  // is worth 3 % of the surface misclassified, c = 0.03^2 / 0.03 = 0.03.
  // 0 = squared error alone (the build before); plans stored without the
  // key restore with 0.
  double misclassification_cost = 0.03;
  // kBoundary: a drag also gains by settling the mu of a material known too
  // roughly to tell from another's, at misclassification_cost a point
  // (boundary_selection.h, MaterialMuRiskGain). Measured in-process on the
  // held-out pebble over 30 seeds (7-36): its 6 mm masonite strip was
  // scored below 85 % on 4 of them (0 % once) and on none with it (docs/
  // method.md). Plans stored without the key restore with false.
  bool material_mu_risk = true;
  // kBoundary: at a boundary between two materials, what a point given the
  // wrong material costs is misclassification_cost times w = the mean
  // material's area over the smaller side's material's area (both the
  // map's), clamped to [1, small_material_weight_max]. The goals judge
  // every region on its own share classified right, and on twin_band_egg
  // seed 13 a 14 mm cap that two drags found was left with its far side
  // unseen (76 %) while the budget went to long bands. Tried with 4 and not
  // adopted (docs/method.md, "Small materials' boundaries weighed more"):
  // in-process 246 of 256 goals met either way, but held_egg seed 1 lost
  // a region outright. 1 = every boundary alike (the build before, and
  // what plans stored without the key restore with).
  double small_material_weight_max = 1.0;
  // kBoundary: a drag's far-from-data gain at a vertex is what bringing its
  // distance to data down to the drag's path takes off its far variance
  // (boundary_selection.h), not all of it: a vertex 3 mm from data that a
  // drag passes 5 mm away is no nearer data after it. Counted in full, the
  // corridors of well-sampled surface kept a third of an open corridor's
  // gain, and the plan spread drags there instead of settling boundaries.
  // Measured in-process on 19 scenes x seeds 1-16 (docs/method.md, "A
  // drag's far gain is what it brings nearer"): goals met 283 -> 294 of
  // 304, the held-out tool handle 5 -> 14 of 16. false = all of it within
  // the corridor (the build before, and what plans stored without the key
  // restore with).
  bool far_gain_expected = true;
  // kBoundary: the sites chosen in one selection are issued in the order
  // they were chosen: the one with the largest gain first, each next one
  // chosen with those before it counted as covered. false = in the plan's
  // issue order (lowest level first, then the seeded shuffle), which with
  // one rig issued whichever of the `lookahead` choices sat on the coarsest
  // level, and re-made the others after its answer. Off: measured
  // in-process on 19 scenes x seeds 1-8, goals met 145 -> 140 of 152
  // (docs/method.md, "A selection issued in the order it was chosen").
  // Plans stored without the key restore with false.
  bool issue_selected_by_gain = false;
  // kBoundary: a coarsest-level site dragged after data came in, where no
  // boundary calls for a direction, takes whichever of its three varied
  // orientations (drag_direction.h) gains most: mostly, whose path brings
  // the most surface nearer data. false = the site's own orientation, by
  // its shuffle key (the build before, and what plans stored without the
  // key restore with). Tried, not adopted: 79 -> 72 of 80 jobs met the goals
  // on seeds 5-8 (docs/method.md, "Coarse drags laid by gain for coverage").
  bool coarse_direction_by_gain = false;
  // kBoundary: a coarsest-level site not yet issued is skipped when a
  // measured drag's data window passed within this share of the drag length
  // of it: within a quarter of the length either side of its path the map
  // is that drag's data (the selector's corridor, boundary_selection.h), so
  // dragging there again measures what is known. 0 = every coarsest-level
  // site is dragged. The service issues a kBoundary job's commands only as
  // rigs ask (server/jobs/command_lookahead.h), so coarse sites are still
  // pending when drags come in. Measured in docs/method.md section 5. Plans
  // stored without the key restore with 0 (what they were made with).
  double coverage_skip_share = 0.25;
  // kBoundary: ... and within this (larger) share of the drag length when
  // that drag found no change along it. Half the length is the reach the
  // selector itself counts as covered by a drag (boundary_selection.h): a
  // drag that saw one material all along settles that much round it, while
  // near one that crossed a boundary the coarse pass goes on looking (the
  // boundary may turn, or a band beside it begin). Measured in
  // docs/method.md section 5 (in-process and through the service, six
  // seeds). Below coverage_skip_share it changes nothing; plans stored
  // without the key restore with 0.
  double quiet_coverage_skip_share = 0.5;

  bool IsValid(std::string* why) const;
};

std::string_view PlanModeName(PlanMode mode);  // "adaptive", "uniform", "uncertainty", "boundary"
std::optional<PlanMode> ParsePlanMode(std::string_view name);

}  // namespace surfmap
