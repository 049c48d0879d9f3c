// surfmap-mapsim: maps scenes entirely in-process (simulated rig -> FitTrace
// -> sampling plan -> map) and scores every map on the scene's true surface.
//
//   surfmap-mapsim [--scene NAME ...|all] [--mode evidence|boundary|adaptive|uncertainty|uniform|uniform-spread]
//
// --mode evidence (the default) runs, per scene: the default job (the
// boundary plan with its default budget, the region map); the build before
// line samples (the paper's threshold rule over levels 0..1 at threshold 4,
// the demo's job, one value per site, harmonic map); and uniform sampling at
// the default job's sample count (farthest-point spread, region map and
// harmonic map). It prints one table row per run and the per-region score
// of the default job.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <numbers>
#include <fstream>
#include <iostream>
#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include "absl/strings/str_format.h"
#include "clients/mapsim/mapping_report.h"
#include "clients/mapsim/mapping_run.h"
#include "clients/sim/rig/scene.h"
#include "surfmap_version.h"

namespace surfmap::mapsim {
namespace {

const std::vector<std::string> kAllScenes = {"bottle",      "plate",      "banded_vase",
                                             "strip_block", "dotted_egg", "torus_handle"};

bool WriteFile(const std::string& path, const std::string& bytes) {
  std::ofstream out(path, std::ios::binary);
  out << bytes;
  out.close();
  if (!out) {
    std::fprintf(stderr, "error: cannot write %s\n", path.c_str());
    return false;
  }
  return true;
}

// "out.png" -> "out-bottle-3.png" when several runs write files.
std::string PathFor(const std::string& path, const std::string& scene, int index, bool several) {
  if (!several) return path;
  std::filesystem::path p(path);
  return (p.parent_path() / absl::StrFormat("%s-%s-%d%s", p.stem().string(), scene, index, p.extension().string()))
      .string();
}

// --NAME-link-crossing-deg: BoundaryLinkOptions::min_crossing_cos given in
// degrees off perpendicular (its default shown in degrees; set only when given).
void AddCrossingDegOption(CLI::App& app, const std::string& name, BoundaryLinkOptions& links,
                          const std::string& help) {
  const double default_deg = std::acos(links.min_crossing_cos) * 180.0 / std::numbers::pi;
  app.add_option_function<double>(
         name, [&links](double deg) { links.min_crossing_cos = std::cos(deg * std::numbers::pi / 180.0); }, help)
      ->check(CLI::Range(0.0, 90.0))
      ->default_str(absl::StrFormat("%.1f", default_deg));
}

// An angle in degrees, 0 to max_deg, its default shown in --help.
void AddDegreesOption(CLI::App& app, const std::string& name, double& degrees, double max_deg,
                      const std::string& help) {
  app.add_option(name, degrees, help)->check(CLI::Range(0.0, max_deg))->capture_default_str();
}

int Main(int argc, char** argv) {
  CLI::App app{"surfmap-mapsim: map scenes in-process with the simulated rig and score the maps on the true surface"};
  app.set_version_flag("--version", std::string("surfmap-mapsim ") + surfmap::kSurfmapVersion);
  std::vector<std::string> scenes = {"bottle"};
  std::string mode = "evidence";
  std::string map = "regions";
  int coarsest = 0, finest = -1, budget = 0, points = 5000;
  int min_region_points = SurfaceScoreOptions{}.min_region_points;
  double threshold = 4.0;
  std::uint64_t seed = 1;
  std::string property = "friction";
  std::string png, ply, json_path;
  int rig_level = 3;
  bool details = false;
  bool follow = false;
  double continuation_prior = SamplingPlanOptions{}.continuation_prior;
  double misclassification_cost = SamplingPlanOptions{}.misclassification_cost;
  bool material_mu_risk = SamplingPlanOptions{}.material_mu_risk;
  double small_material_weight_max = SamplingPlanOptions{}.small_material_weight_max;
  bool far_gain_expected = SamplingPlanOptions{}.far_gain_expected;
  bool issue_by_gain = SamplingPlanOptions{}.issue_selected_by_gain;
  bool coarse_by_gain = SamplingPlanOptions{}.coarse_direction_by_gain;
  bool friction_boundary_cost = !SamplingPlanOptions{}.boundary_cost_follows_property;
  double coverage_skip_share = SamplingPlanOptions{}.coverage_skip_share;
  double quiet_coverage_skip_share = SamplingPlanOptions{}.quiet_coverage_skip_share;
  bool plan_split = MappingRunOptions{}.plan_split_against_materials;
  bool map_split = MappingRunOptions{}.map_split_against_materials;
  bool plan_assign = MappingRunOptions{}.plan_assign_by_texture;
  bool map_assign = MappingRunOptions{}.map_assign_by_texture;
  BoundaryLinkOptions map_links = MappingRunOptions{}.map_link_options;
  int map_mu_pieces = MappingRunOptions{}.map_min_fitted_pieces_for_mu;
  bool map_move_only_alike = MappingRunOptions{}.map_move_only_to_alike_material;
  bool map_ignore_unconfirmed_ends = MappingRunOptions{}.map_ignore_unconfirmed_end_pieces;
  bool map_transition_crossings = MappingRunOptions{}.map_transition_crossings;
  double map_transition_max_mm = MappingRunOptions{}.map_transition_max_mm;
  bool map_known_texture_bands = MappingRunOptions{}.map_known_texture_bands;
  double map_mu_min_mm = MappingRunOptions{}.map_min_mu_piece_mm;
  bool plan_link_materials = MappingRunOptions{}.plan_link_materials;
  BoundaryLinkOptions plan_links = MappingRunOptions{}.plan_link_options;
  double change_guard_mm = FitOptions{}.change_guard_mm;
  int noise_replicates = FitOptions{}.noise_replicates;
  double series_normal_mm = FitOptions{}.series.halfwidth_mm;
  bool series_follow_samples = FitOptions{}.series.follow_samples;
  bool map_link_materials = MappingRunOptions{}.map_link_materials;
  app.add_option("--scene", scenes, "scene names (clients/sim/scenes, $SURFMAP_SCENES), or 'all'")->capture_default_str();
  app.add_option("--mode", mode, "evidence | boundary | adaptive | uncertainty | uniform | uniform-spread")
      ->check(CLI::IsMember({"evidence", "boundary", "adaptive", "uncertainty", "uniform", "uniform-spread"}))
      ->capture_default_str();
  app.add_option("--map", map, "regions | harmonic (single modes)")
      ->check(CLI::IsMember({"regions", "harmonic"}))
      ->capture_default_str();
  app.add_option("--coarsest", coarsest, "coarsest level")->capture_default_str();
  app.add_option("--finest", finest, "the plan's finest level (-1: two levels coarser than the map's)")->capture_default_str();
  app.add_option("--threshold", threshold, "adaptive: refine where the texture distance exceeds this")
      ->capture_default_str();
  app.add_option("--budget", budget, "sample budget (0: the mode's default)")->capture_default_str();
  app.add_option("--seed", seed, "plan order and rig noise")->capture_default_str();
  app.add_option("--points", points, "random points on the true surface to score on")->capture_default_str();
  app.add_option("--min-region-points", min_region_points,
                 "each region's row is scored on at least this many of its points (extra points drawn inside small "
                 "regions; the overall share uses --points alone; 0: none)")
      ->check(CLI::Range(0, 100'000))
      ->capture_default_str();
  app.add_option("--property", property, "what the texture distance compares: friction | roughness | both")
      ->check(CLI::IsMember({"friction", "roughness", "both"}))
      ->capture_default_str();
  app.add_option("--rig-level", rig_level, "Loop level of the simulated rig's surface")->capture_default_str();
  app.add_flag("--follow-boundaries", follow,
               "boundary plans follow every boundary a drag crossed before choosing by uncertainty (an experiment)");
  app.add_option("--continuation-prior", continuation_prior,
                 "boundary plans: weight of a drag across where a crossed boundary would go on straight (0: off, the build before)")
      ->check(CLI::Range(0.0, 1.0))
      ->capture_default_str();
  app.add_option("--misclassification-cost", misclassification_cost,
                 "boundary plans: what a point given the wrong material costs, mu^2, on top of its squared error "
                 "(boundary_selection.h; 0: squared error alone, the build before)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  app.add_option("--material-mu-risk", material_mu_risk,
                 "boundary plans: a drag also gains by settling a material's mu known too roughly to tell from "
                 "another's (boundary_selection.h; false: the build before) (true|false)")
      ->capture_default_str();
  app.add_option("--small-material-weight", small_material_weight_max,
                 "boundary plans: a point given the wrong material at a small material's boundary costs up to this "
                 "many times --misclassification-cost (sampling_plan_options.h; 1: every boundary alike, the build "
                 "before)")
      ->check(CLI::Range(1.0, 1e6))
      ->capture_default_str();
  app.add_option("--far-expected", far_gain_expected,
                 "boundary plans: a drag's far-from-data gain is what bringing data nearer takes off, not the "
                 "corridor's whole far variance (sampling_plan_options.h; false: the build before) (true|false)")
      ->capture_default_str();
  app.add_option("--issue-by-gain", issue_by_gain,
                 "boundary plans issue a selection's sites in the order they were chosen, the largest gain first "
                 "(sampling_plan_options.h; false: the plan's issue order, the build before) (true|false)")
      ->capture_default_str();
  app.add_option("--coarse-by-gain", coarse_by_gain,
                 "boundary plans drag a coarsest-level site in whichever of its three varied orientations gains most "
                 "(sampling_plan_options.h; false: its own by the seeded key, the build before) (true|false)")
      ->capture_default_str();
  app.add_flag("--friction-boundary-cost", friction_boundary_cost,
               "boundary plans weigh a boundary by its mu jump alone whatever --property says (the build before)");
  app.add_option("--coverage-skip-share", coverage_skip_share,
                 "boundary plans skip a coarsest-level site a measured drag passed within this share of the drag "
                 "length of (0: drag every one)")
      ->capture_default_str();
  app.add_option("--quiet-coverage-skip-share", quiet_coverage_skip_share,
                 "... and within this share of one that found no change along it (at or below "
                 "--coverage-skip-share: off, the build before)")
      ->capture_default_str();
  app.add_option("--plan-split", plan_split,
                 "the plan's map splits pieces against its materials' textures (true|false)")
      ->capture_default_str();
  app.add_option("--map-split", map_split,
                 "the scored map splits pieces against its materials' textures (true|false); "
                 "differing from --plan-split alone compares the two on the same drags")
      ->capture_default_str();
  app.add_option("--plan-assign", plan_assign,
                 "the plan's map moves regions to the material whose texture fits them best (true|false)")
      ->capture_default_str();
  app.add_option("--map-assign", map_assign,
                 "the scored map moves regions to the material whose texture fits them best (true|false); "
                 "differing from --plan-assign alone compares the two on the same drags")
      ->capture_default_str();
  AddDegreesOption(app, "--map-extension-turn", map_links.max_extension_turn_deg, 90.0,
                   "the scored map carries chains of boundary links on through oblique crossings whose chord turns by "
                   "at most this many degrees (0: off, the build before)");
  AddDegreesOption(app, "--map-line-turn", map_links.max_line_turn_deg, 90.0,
                   "the scored map joins three oblique crossings of a boundary in a row when the chord turns at the "
                   "middle one by at most this many degrees (boundary_lines.h; 0: off, the build before)");
  app.add_option("--map-dot-radius", map_links.max_dot_radius_mm,
                 "the scored map draws a circle through the crossings round a dot of at most this radius, mm "
                 "(boundary_dots.h; 0: off, the build before)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  app.add_option("--map-dot-data-offset", map_links.max_dot_data_offset_mm,
                 "the scored map refuses a dot's circle for data more than this many mm on its wrong side "
                 "(boundary_dots.h; 0.25: the build before, on the same drags)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  app.add_option("--map-chain-ends-reach-past-short-links", map_links.chain_ends_reach_past_short_links,
                 "the scored map gives a chain whose last link is shorter than a corner's shortest an end all the "
                 "same, directed from farther back along it (boundary_chains.h; false: the build before, on the same "
                 "drags)")
      ->capture_default_str();
  app.add_option("--map-line-chord-mm", map_links.min_line_chord_mm,
                 "the scored map joins three crossings in a line by chords this short when its outer two are a "
                 "corner link apart (boundary_lines.h; 4: the build before, on the same drags)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  app.add_option("--map-corner-side-past-reach", map_links.corner_side_checked_past_reach,
                 "the scored map takes a corner's side of one link within the reach as straight when the link "
                 "after it runs on (boundary_corners.h; false: the build before, on the same drags)")
      ->capture_default_str();
  app.add_option("--map-corner-side-may-end-chain", map_links.corner_side_may_end_its_chain,
                 "the scored map takes a corner's side of one link whose chain ends there as straight when the "
                 "other side runs straight (boundary_corners.h; false: the build before, on the same drags)")
      ->capture_default_str();
  app.add_option("--map-square-corners", map_links.square_corner_from_one_side,
                 "the scored map draws a cut corner square to its one straight side when the other side shows no "
                 "direction (boundary_corners.h; false: the build before, on the same drags)")
      ->capture_default_str();
  app.add_option("--map-corner-side-to-next-corner", map_links.corner_side_stops_at_next_corner,
                 "the scored map takes a corner's side as its straight run of two links or more when it turns "
                 "round the next corner within the reach (boundary_corners.h; false: the build before, on the "
                 "same drags)")
      ->capture_default_str();
  app.add_option("--map-dot-min-arc", map_links.min_dot_arc_deg,
                 "the scored map draws a dot whose crossings span at least this arc of its circle, degrees, "
                 "when other regions' data close the rest (boundary_dots.h; 180: only crossings that surround "
                 "its centre, the build before)")
      ->capture_default_str();
  app.add_option("--map-dot-ring", map_links.dot_ring_radii,
                 "the scored map checks a dot's ring out to this many of its radii from its centre: its own "
                 "region's data there refuse it, other regions' close a one-sided dot's gap (boundary_dots.h)")
      ->capture_default_str();
  app.add_option("--map-dot-contradicted-chords", map_links.max_dot_contradicted_chord_share,
                 "the scored map leaves out a dot's chords that data contradict, while at most this share of them "
                 "are, and draws the rest of its circle (boundary_dots.h; 0: the build before, on the same drags)")
      ->check(CLI::Range(0.0, 1.0))
      ->capture_default_str();
  app.add_option("--map-dot-outlier", map_links.max_dot_outlier_mm,
                 "the scored map lets one crossing of a dot crossed six times or more lie this far off the circle "
                 "through the others, mm (boundary_dots.h; 0: off, the build before)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  app.add_option("--map-rectangle-sides-closed-by-data", map_links.rectangle_sides_closed_by_data,
                 "the scored map draws a rectangle's side no drag crossed clear of its corners when other regions' "
                 "data run along it just outside (boundary_rectangles.h; false: the build before, on the same drags)")
      ->capture_default_str();
  app.add_option("--map-rectangle-patch-sheet", map_links.rectangle_data_on_patch_sheet,
                 "the scored map checks a rectangle against data within 2 mm of the band off its plane where its "
                 "crossings lie (boundary_rectangles.h; false: data as far off as half its longer side, the build "
                 "before, on the same drags)")
      ->capture_default_str();
  app.add_option("--map-rectangle-side", map_links.max_rectangle_side_mm,
                 "the scored map draws a rectangle through the crossings round a small patch whose sides are at most "
                 "this long, mm (boundary_rectangles.h; 0: off, the build before)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  app.add_option("--map-dot-grazing-crossings", map_links.dot_grazing_crossings_on_circle,
                 "the scored map lets a crossing of a drag that grazed a dot count when it lies on the circle "
                 "(boundary_dots.h; false: the build before, on the same drags)")
      ->capture_default_str();
  app.add_option("--map-corner-side-residual", map_links.max_corner_side_residual_mm,
                 "the scored map replaces a link that cuts a corner off by the corner when the chains on both "
                 "sides run straight to within this many mm (boundary_corners.h; 0: off, the build before)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  app.add_option("--map-move-only-alike", map_move_only_alike,
                 "the scored map moves a misfit piece only to a material its mu is alike to (true|false; "
                 "false: the build before, on the same drags)")
      ->capture_default_str();
  app.add_option("--map-ignore-unconfirmed-ends", map_ignore_unconfirmed_ends,
                 "the scored map's boundaries are not refused by the data of a drag's end piece too short and too "
                 "like its neighbour to mark a crossing (true|false; false: the build before, on the same drags)")
      ->capture_default_str();
  app.add_option("--map-transition-crossings", map_transition_crossings,
                 "the scored map marks one crossing in the middle of a short piece between two changes that reads "
                 "between its neighbours, and that piece refuses no boundary (true|false; false: the build before, "
                 "on the same drags)")
      ->capture_default_str();
  app.add_option("--map-transition-mm", map_transition_max_mm,
                 "... when that piece is shorter than this many mm (RegionMapOptions::max_transition_piece_mm; 1.5: "
                 "the build before, on the same drags)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  app.add_option("--map-known-bands", map_known_texture_bands,
                 "the scored map's split of pieces against its materials' textures also tests a band of one texture "
                 "inside another where no single split is kept (KnownTextureSplitOptions::test_bands; false: the build "
                 "before, on the same drags)")
      ->capture_default_str();
  app.add_option("--map-mu-pieces", map_mu_pieces,
                 "the scored map pools a material's mu from its pieces long enough for a roughness fit when it has at "
                 "least this many (0: from every piece, the build before)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  app.add_option("--map-mu-min-mm", map_mu_min_mm,
                 "... counting a piece as long enough when its extent is at least this many mm (0: when it has its "
                 "own roughness fit, the build before)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  app.add_option("--plan-link-materials", plan_link_materials,
                 "the plan's map links crossings of one boundary between materials, not regions (true|false)")
      ->capture_default_str();
  app.add_option("--map-link-materials", map_link_materials,
                 "the scored map links crossings of one boundary between materials, not regions (true|false; false: "
                 "the build before)")
      ->capture_default_str();
  app.add_option("--plan-link-length", plan_links.max_length_mm,
                 "the plan's map joins crossings of a boundary at most this many mm apart (boundary_links.h)")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  AddCrossingDegOption(app, "--plan-link-crossing-deg", plan_links,
                       "the plan's map links two crossings only when both drags ran within this many degrees of "
                       "perpendicular to the link");
  AddDegreesOption(app, "--plan-curve-turn-deg", plan_links.max_curve_turn_deg, 180.0,
                   "the plan's map draws links as curves through their chain (as --map-curve-turn-deg; 0: chords)");
  AddDegreesOption(app, "--plan-extension-turn", plan_links.max_extension_turn_deg, 90.0,
                   "the plan's map carries chains of links on (as --map-extension-turn; 0: off)");
  app.add_option("--series-follow-samples", series_follow_samples,
                 "each pass's roughness series is its own samples one step apart (force_variation.h; false: the "
                 "nearest sample to each point of a fixed grid, estimator version 8)")
      ->capture_default_str();
  app.add_option("--series-normal-mm", series_normal_mm,
                 "the roughness series reads each force against the pair normals averaged over +- this many mm "
                 "(force_variation.h; 0: each pair's own normal, estimator version 8)")
      ->check(CLI::Range(0.0, 10.0))
      ->capture_default_str();
  app.add_option("--noise-replicates", noise_replicates,
                 "replicates propagating the pause's sensor noise to the roughness series (series_noise.h; 0: the "
                 "white model sigma^2 (1 + mu^2), estimator version 7)")
      ->check(CLI::Range(0, 64))
      ->capture_default_str();
  app.add_option("--change-guard-mm", change_guard_mm,
                 "a piece's roughness fit leaves this many mm out next to each change it ends at (FitOptions)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  app.add_option("--map-link-length", map_links.max_length_mm,
                 "the scored map joins crossings of a boundary at most this many mm apart (boundary_links.h)")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  AddCrossingDegOption(app, "--map-link-crossing-deg", map_links,
                       "the scored map links two crossings only when both drags ran within this many degrees of "
                       "perpendicular to the link (boundary_links.h)");
  AddDegreesOption(app, "--map-curve-turn-deg", map_links.max_curve_turn_deg, 180.0,
                   "the scored map draws a link as a curve through its chain where the chain turns by at most this "
                   "many degrees at its ends (boundary_curves.h; 0: every link a chord, the build before)");
  app.add_option("--map-corner-reach", map_links.corner_reach_mm,
                 "the scored map draws a corner where two chain ends, carried straight on, meet within this many mm "
                 "of both (boundary_corners.h; 0: no corners; 20: the build before, on the same drags)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  AddDegreesOption(app, "--map-corner-max-turn", map_links.max_corner_turn_deg, 180.0,
                   "the scored map draws a corner where the boundary turns by at most this many degrees (boundary_"
                   "corners.h; a triangle's 60-degree point turns 120; 120: the build before, on the same drags)");
  AddDegreesOption(app, "--map-hanging-link-angle", map_links.min_hanging_link_angle_deg, 90.0,
                   "a line takes a mark's side from a hanging link only when that link runs at least this many degrees "
                   "off the line (boundary_lines.h; 90: never, the build before)");
  AddDegreesOption(app, "--map-line-crossing", map_links.max_line_crossing_deg, 90.0,
                   "a line's drags must cross its chords within this many degrees of perpendicular (boundary_lines.h; "
                   "75: the build before, on the same drags)");
  app.add_option("--map-corner-side-reach", map_links.corner_side_reach_mm,
                 "the scored map checks a cut corner's sides for running straight over this many mm from the "
                 "chord's ends (boundary_corners.h; 0: no cut corners replaced)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  app.add_option("--map-extension-length", map_links.max_extension_length_mm,
                 "the scored map carries a chain of links on to a crossing at most this many mm from its end")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  app.add_flag("--details", details, "per-region scores of every run (evidence: of the default job only otherwise)");
  app.add_option("--png", png, "map image (grey scale, samples and drag paths), one per run when several");
  app.add_option("--ply", ply, "map as PLY, one per run when several");
  app.add_option("--json", json_path, "scores and probes as JSON");
  CLI11_PARSE(app, argc, argv);
  if (scenes.size() == 1 && scenes[0] == "all") scenes = kAllScenes;

  MappingRunOptions base;
  base.coarsest_level = coarsest;
  base.finest_level = finest;
  base.threshold = threshold;
  base.sample_budget = budget;
  base.seed = seed;
  base.follow_boundaries = follow;
  base.continuation_prior = continuation_prior;
  base.misclassification_cost = misclassification_cost;
  base.material_mu_risk = material_mu_risk;
  base.small_material_weight_max = small_material_weight_max;
  base.far_gain_expected = far_gain_expected;
  base.issue_selected_by_gain = issue_by_gain;
  base.coarse_direction_by_gain = coarse_by_gain;
  base.boundary_cost_follows_property = !friction_boundary_cost;
  base.coverage_skip_share = coverage_skip_share;
  base.quiet_coverage_skip_share = quiet_coverage_skip_share;
  base.plan_split_against_materials = plan_split;
  base.map_split_against_materials = map_split;
  base.plan_assign_by_texture = plan_assign;
  base.map_assign_by_texture = map_assign;
  base.map_move_only_to_alike_material = map_move_only_alike;
  base.map_ignore_unconfirmed_end_pieces = map_ignore_unconfirmed_ends;
  base.map_transition_crossings = map_transition_crossings;
  base.map_transition_max_mm = map_transition_max_mm;
  base.map_known_texture_bands = map_known_texture_bands;
  base.map_link_options = map_links;
  base.map_min_fitted_pieces_for_mu = map_mu_pieces;
  base.map_min_mu_piece_mm = map_mu_min_mm;
  base.plan_link_materials = plan_link_materials;
  base.plan_link_options = plan_links;
  base.fit.change_guard_mm = change_guard_mm;
  base.fit.noise_replicates = noise_replicates;
  base.fit.series.halfwidth_mm = series_normal_mm;
  base.fit.series.follow_samples = series_follow_samples;
  base.map_link_materials = map_link_materials;
  base.map = map == "harmonic" ? MapKind::kHarmonic : MapKind::kRegions;
  base.property = ParseTextureProperty(property).value_or(TextureProperty::kFriction);  // CLI11 checked the name
  SurfaceScoreOptions score_options;
  score_options.points = points;
  score_options.min_region_points = min_region_points;

  nlohmann::json all = nlohmann::json::array();
  std::string table;
  int files = 0;
  for (const std::string& scene_name : scenes) {
    absl::StatusOr<Scene> scene = LoadSceneByName(scene_name);
    if (!scene.ok()) {
      std::fprintf(stderr, "error: %s\n", std::string(scene.status().message()).c_str());
      return 1;
    }
    absl::StatusOr<std::unique_ptr<MappingBench>> bench =
        MappingBench::Create(*std::move(scene), seed, rig_level, -1, score_options);
    if (!bench.ok()) {
      std::fprintf(stderr, "error: %s: %s\n", scene_name.c_str(), std::string(bench.status().message()).c_str());
      return 1;
    }
    std::vector<MappingRunResult> runs;
    auto run = [&](MappingRunOptions options) -> bool {
      absl::StatusOr<MappingRunResult> result = RunMapping(**bench, options);
      if (!result.ok()) {
        std::fprintf(stderr, "error: %s: %s run: %s\n", scene_name.c_str(),
                     std::string(RunModeName(options)).c_str(), std::string(result.status().message()).c_str());
        return false;
      }
      runs.push_back(*std::move(result));
      return true;
    };
    if (mode == "evidence") {
      MappingRunOptions job = base;  // the default job: only the mode is given
      job.mode = PlanMode::kBoundary;
      job.map = MapKind::kRegions;
      job.coarsest_level = 0;
      job.finest_level = -1;
      job.sample_budget = 0;
      if (!run(job)) return 1;
      MappingRunOptions before = base;  // the demo's job on the build before line samples
      before.mode = PlanMode::kAdaptive;
      before.map = MapKind::kHarmonic;
      before.coarsest_level = 0;
      before.finest_level = 1;
      before.threshold = 4.0;
      before.sample_budget = 0;
      if (!run(before)) return 1;
      MappingRunOptions uniform = base;
      uniform.mode = PlanMode::kUniform;
      uniform.uniform_spread = true;
      uniform.finest_level = -1;
      uniform.sample_budget = runs.front().measured();
      uniform.map = MapKind::kRegions;
      if (!run(uniform)) return 1;
      uniform.map = MapKind::kHarmonic;
      if (!run(uniform)) return 1;
    } else {
      MappingRunOptions options = base;
      // CLI11 checked the name: a plan mode's, or "uniform-spread".
      options.uniform_spread = mode == "uniform-spread";
      options.mode = options.uniform_spread ? PlanMode::kUniform : ParsePlanMode(mode).value_or(PlanMode::kBoundary);
      if (!run(options)) return 1;
    }
    const std::string rows = FormatRunTable(scene_name, (*bench)->control_vertices(), runs);
    table += table.empty() ? rows : rows.substr(rows.find('\n') + 1);
    std::printf("%s", rows.c_str());
    for (std::size_t i = 0; i < runs.size(); ++i) {
      if (details || i == 0) std::printf("%s", FormatSurfaceScore(runs[i].score, RunLabel(runs[i])).c_str());
      if (details) std::printf("%s", FormatMapRegions(runs[i], (*bench)->scene()).c_str());
    }
    std::fflush(stdout);
    const bool several = scenes.size() > 1 || runs.size() > 1;
    for (std::size_t i = 0; i < runs.size(); ++i) {
      nlohmann::json j = RunToJson(runs[i]);
      j["scene"] = scene_name;
      all.push_back(std::move(j));
      if (!png.empty()) {
        absl::StatusOr<std::string> bytes = RunPng(**bench, runs[i]);
        if (!bytes.ok()) {
          std::fprintf(stderr, "error: png: %s\n", std::string(bytes.status().message()).c_str());
          return 1;
        }
        if (!WriteFile(PathFor(png, scene_name, static_cast<int>(i), several), *bytes)) return 1;
        ++files;
      }
      if (!ply.empty()) {
        absl::StatusOr<std::string> text = RunPly(**bench, runs[i]);
        if (!text.ok()) {
          std::fprintf(stderr, "error: ply: %s\n", std::string(text.status().message()).c_str());
          return 1;
        }
        if (!WriteFile(PathFor(ply, scene_name, static_cast<int>(i), several), *text)) return 1;
      }
    }
  }
  if (scenes.size() > 1) std::printf("\nall scenes:\n%s", table.c_str());
  if (!json_path.empty()) {
    if (!WriteFile(json_path, nlohmann::json{{"runs", all}}.dump(2) + "\n")) return 1;
  }
  return 0;
}

}  // namespace
}  // namespace surfmap::mapsim

int main(int argc, char** argv) { return surfmap::mapsim::Main(argc, argv); }
