// A whole mapping run in one process, no network: the sampling plan issues
// probe commands, the simulated rig executes them on the scene, FitTrace fits
// each trace, the fit goes back to the plan, until the plan is complete; then
// the map is built from the measured drags and scored on the scene's true
// surface (clients/sim/rig/surface_score.h).
//
// The rig is seeded per site and drag direction (command id = f(vertex,
// attempt)), not per command sequence, so the same drag gives the same trace
// in every mode: runs of different modes differ only in where they sample.
#pragma once

#include <algorithm>
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>
#include "absl/status/statusor.h"
#include "clients/sim/rig/scene.h"
#include "clients/sim/rig/simulated_rig.h"
#include "clients/sim/rig/surface_score.h"
#include "server/estimate/fit_trace.h"
#include "server/estimate/line_sample.h"
#include "server/estimate/texture.h"
#include "server/map/map_level.h"
#include "server/mesh/loop_surface.h"
#include "server/plan/reachability.h"
#include "server/plan/sampling_plan_options.h"

namespace surfmap::mapsim {


enum class MapKind {
  kRegions,   // RegionMap from every drag's pieces on the bench's map level
  kHarmonic,  // FrictionMap: one value per site, harmonic over the plan's finest level (the build before line samples)
};
std::string_view MapKindName(MapKind kind);  // "regions", "harmonic"

struct MappingRunOptions {
  // The sampling mode is the plan's own (server/plan PlanMode; the service
  // maps the API's SamplingMode to it), so a run plans as a job would.
  PlanMode mode = PlanMode::kBoundary;
  // With kUniform: no plan; `sample_budget` vertices of the map's level
  // spread by farthest-point sampling (Euclidean, from a seeded random first
  // vertex), dragged in orientations varied as the boundary plan's first
  // drags are: a uniform design at any sample count, for comparisons at
  // equal counts.
  bool uniform_spread = false;
  MapKind map = MapKind::kRegions;
  int coarsest_level = 0;
  // The plan's max level (and the harmonic map's level; the boundary plan's
  // candidates and its own map); -1 = the bench's plan level, one coarser
  // than the map level (~4 mm edges: enough to decide where to drag, at a
  // quarter of the cost of rebuilding the plan's map after every drag).
  int finest_level = -1;
  double threshold = 2.0;        // kAdaptive, in TextureDistance units
  TextureProperty property = TextureProperty::kFriction;  // what the texture distance compares
  int sample_budget = 0;         // 0 = the mode's default (kUncertainty and kUniformSpread need one)
  std::uint64_t seed = 1;        // plan issue order, rig noise, kUniformSpread's first vertex
  Reachability reach;            // per job: sites outside are not planned
  bool follow_boundaries = false;  // kBoundary: SamplingPlanOptions::follow_boundaries
  double continuation_prior = SamplingPlanOptions{}.continuation_prior;  // kBoundary
  double misclassification_cost = SamplingPlanOptions{}.misclassification_cost;  // kBoundary
  bool material_mu_risk = SamplingPlanOptions{}.material_mu_risk;                // kBoundary
  double small_material_weight_max = SamplingPlanOptions{}.small_material_weight_max;  // kBoundary
  bool far_gain_expected = SamplingPlanOptions{}.far_gain_expected;                    // kBoundary
  bool issue_selected_by_gain = SamplingPlanOptions{}.issue_selected_by_gain;          // kBoundary
  bool coarse_direction_by_gain = SamplingPlanOptions{}.coarse_direction_by_gain;      // kBoundary
  bool boundary_cost_follows_property = SamplingPlanOptions{}.boundary_cost_follows_property;  // kBoundary
  double coverage_skip_share = SamplingPlanOptions{}.coverage_skip_share;  // kBoundary
  double quiet_coverage_skip_share = SamplingPlanOptions{}.quiet_coverage_skip_share;  // kBoundary
  // RegionMapOptions::split_against_materials for the plan's own map and for
  // the map scored: as in a job, the plan's off and the map's on; the map's
  // alone differing compares the two on the same drags.
  bool plan_split_against_materials = false;
  bool map_split_against_materials = true;
  // RegionMapOptions::assign_by_texture, likewise.
  bool plan_assign_by_texture = false;
  bool map_assign_by_texture = true;
  // RegionMapOptions::move_only_to_alike_material of the map scored (the
  // plan's map keeps its own default): false alone compares the build
  // before on the same drags.
  bool map_move_only_to_alike_material = RegionMapOptions{}.move_only_to_alike_material;
  // RegionMapOptions::boundaries_ignore_unconfirmed_end_pieces of the map
  // scored: false alone compares the build before on the same drags.
  bool map_ignore_unconfirmed_end_pieces = RegionMapOptions{}.boundaries_ignore_unconfirmed_end_pieces;
  // RegionMapOptions::transition_pieces_mark_one_crossing for the scored map.
  bool map_transition_crossings = RegionMapOptions{}.transition_pieces_mark_one_crossing;
  // RegionMapOptions::max_transition_piece_mm for the scored map.
  double map_transition_max_mm = RegionMapOptions{}.max_transition_piece_mm;
  // KnownTextureSplitOptions::test_bands of the scored map's split against
  // its materials' textures.
  bool map_known_texture_bands = RegionMapOptions{}.known_split.test_bands;
  // The links of the map scored (the plan's map carries no chain on,
  // PlanRegionMapOptions).
  BoundaryLinkOptions map_link_options;
  // RegionMapOptions::min_fitted_pieces_for_mu of the map scored (the
  // plan's map pools every piece).
  int map_min_fitted_pieces_for_mu = RegionMapOptions{}.min_fitted_pieces_for_mu;
  double map_min_mu_piece_mm = RegionMapOptions{}.min_mu_piece_mm;  // of the map scored
  // RegionMapOptions::link_materials of the plan's map and of the map scored.
  bool plan_link_materials = PlanRegionMapOptions().link_materials;
  // The links of the plan's own map (PlanRegionMapOptions: 20 mm, 30
  // degrees, chords, no chain carried on).
  BoundaryLinkOptions plan_link_options = PlanRegionMapOptions().links;
  bool map_link_materials = RegionMapOptions{}.link_materials;
  FitOptions fit;

  bool IsValid(std::string* why) const;
};
// PlanModeName(mode), or "uniform-spread".
std::string_view RunModeName(const MappingRunOptions& options);

// One probe as executed: where, and the path the rig dragged.
struct ProbeRecord {
  int vertex = -1;               // vertex of the site
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  Eigen::Vector3d direction = Eigen::Vector3d::Zero();  // as commanded
  std::vector<Eigen::Vector3d> path;  // forward drag path on the surface (empty when the rig failed)
  bool measured = false;         // false: the rig or FitTrace failed (see error)
  bool unreachable = false;      // the rig could not reach or drag there (final)
  std::string error;
  TextureParams fit;             // TextureOf the fit
  LineSample line;               // LineSampleOf the fit
  int changes = 0;               // material changes found inside the drag
};

// One region of a regions map and what its pieces lay on in truth: the
// first thing to read when a region is classified wrong (a mixed piece
// with a small standard error pulls a region's mean; a region of one
// material can spread over another).
struct MapRegionSummary {
  double mu = 0.0;
  double mu_se = 0.0;
  double spread = 0.0;                // pooled per-pair spread
  int pieces = 0;
  int roughness_pieces = 0;
  double vertex_share = 0.0;          // of the map level's vertices in this region
  std::vector<double> truth_mm;       // piece length on each scene material (Scene::materials order)
};

struct MappingRunResult {
  MappingRunOptions options;
  std::vector<ProbeRecord> probes;   // in execution order, failures included
  int skipped = 0;                   // sites the plan skipped (unreachable, budget)
  SurfaceScore score;                // on the scene's true surface
  std::vector<double> map_mu;        // per vertex of the bench's map level (for pictures)
  std::vector<double> map_mu_std;
  std::vector<MapRegionSummary> map_regions;  // regions maps only
  int map_changes = 0;                         // regions maps: crossings between regions,
  int map_links = 0;                           // links drawn between them,
  int map_corners = 0;                         // and corners (boundary_corners.h)
  int map_bridges = 0;                         // and bridges (boundary_bridges.h)
  int map_dots = 0;                            // and dots' circles (boundary_dots.h)
  int map_rectangles = 0;                      // and small patches' rectangles (boundary_rectangles.h)
  int map_split_pieces = 0;                    // pieces split against the materials (piece_resplit.h)
  int map_moved_regions = 0;                   // regions moved by texture (texture_assignment.h)
  int map_moved_pieces = 0;                    // misfit pieces moved by texture (region_map.h)
  int map_dissolved_materials = 0;             // mixtures of two others dissolved (mixture_materials.h)
  double elapsed_s = 0.0;            // the whole run: planning, simulation, fitting, the map
  int measured() const;
};

// The scene's rig, levels and scorer, created once and shared by several
// runs (runs do not modify it).
//
// The plan and the map run where the service's would: on the scene's mesh
// when it is coarse enough to be a control mesh (the hand-made scenes), and
// on the control mesh the service makes of a dense one otherwise (a scan:
// ControlMeshForSpacing at the BOUNDARY default spacing, its limit surface
// projected onto the scan; server/jobs/surface_cache.cc). The rig always
// drags the scene's own surface, as a real rig drags the object.
class MappingBench {
 public:
  // The rig's surface is refined to max(rig_surface_level, map_level - 1)
  // (finer = smoother drag paths; ~2 mm edges are as smooth as a drag needs);
  // map_level -1 = MapLevelFor(control mesh): edges of ~1 mm, the plan
  // kPlanLevelsBelowMap coarser, as the service chooses them. Errors:
  // INVALID_ARGUMENT for levels outside 0..6 or a scene mesh the rig
  // rejects; the scorer's errors; a dense mesh that cannot be simplified.
  static absl::StatusOr<std::unique_ptr<MappingBench>> Create(Scene scene, std::uint64_t rig_seed,
                                                              int rig_surface_level = 3, int map_level = -1,
                                                              const SurfaceScoreOptions& score = {});

  const SimulatedRig& rig() const { return *rig_; }
  const Scene& scene() const { return rig_->scene(); }
  int map_level() const { return map_level_; }
  int plan_level() const { return std::max(0, map_level_ - kPlanLevelsBelowMap); }
  // The plan's and the map's surface: the rig's, or the simplified one.
  const LoopSurface& surface() const { return plan_surface_ ? *plan_surface_ : rig_->surface(); }
  const SurfaceLevel& level(int k) const { return surface().level(k); }
  const SurfaceLevel& map_surface() const { return level(map_level_); }
  const SurfaceScorer& scorer() const { return *scorer_; }
  // Of the control mesh the plan runs on (the budget's unit).
  int control_vertices() const { return static_cast<int>(level(0).limit_positions.size()); }
  // The plan's control mesh is made from the scene's (a scan simplified, facets refined flat).
  bool simplified() const { return plan_surface_ != nullptr; }

 private:
  MappingBench() = default;
  std::unique_ptr<SimulatedRig> rig_;
  std::unique_ptr<LoopSurface> plan_surface_;  // null: the plan runs on the rig's surface
  int map_level_ = 0;
  std::unique_ptr<SurfaceScorer> scorer_;
};

// Runs one mapping. Errors: INVALID_ARGUMENT for invalid options (naming the
// field) or a finest level above the bench's map level, errors of the plan
// or the map (e.g. no site could be measured: FAILED_PRECONDITION).
// Individual probe failures are not errors: they are recorded and reported
// to the plan (RecordFailure, unreachable ones as such), which retries them.
absl::StatusOr<MappingRunResult> RunMapping(const MappingBench& bench, const MappingRunOptions& options);

}  // namespace surfmap::mapsim
