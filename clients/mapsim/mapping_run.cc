#include "clients/mapsim/mapping_run.h"

#include <algorithm>
#include <chrono>
#include <limits>
#include <random>
#include <utility>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"
#include "server/estimate/roughness.h"
#include "server/map/friction_map.h"
#include "server/map/map_level.h"
#include "server/map/region_map.h"
#include "server/mesh/control_simplify.h"
#include "server/mesh/dense_surface.h"
#include "server/mesh/plan_surface.h"
#include "server/mesh/mesh_locator.h"
#include "server/plan/drag_direction.h"
#include "server/plan/plan_request.h"
#include "server/plan/sampling_plan.h"
#include "server/plan/site_order.h"

namespace surfmap::mapsim {
namespace {

// Attempts per site get distinct seeds; sites never share one.
constexpr std::int64_t kAttemptsPerSiteSeed = 16;

std::int64_t SiteCommandId(int vertex, int attempt) {
  return static_cast<std::int64_t>(vertex) * kAttemptsPerSiteSeed + attempt;
}

// Executes and fits one probe. The record says whether it was measured.
ProbeRecord MeasureSite(const SimulatedRig& rig, const MappingRunOptions& options, int vertex, int attempt,
                        const Eigen::Vector3d& position, const Eigen::Vector3d& normal,
                        const Eigen::Vector3d& drag_direction, const ProbeParameters& probe) {
  ProbeRecord record;
  record.vertex = vertex;
  record.position = position;
  record.direction = drag_direction;
  ProbeRequest request;
  request.position = position;  // the rig centres the drag on the site
  request.normal = normal;
  request.drag_direction = drag_direction;
  request.segment_length_mm = probe.segment_length_mm;
  request.speed_mm_s = probe.speed_mm_per_s;
  request.normal_force_n = probe.normal_force_n;
  request.command_id = SiteCommandId(vertex, attempt);
  absl::StatusOr<ProbeExecution> execution = rig.ExecuteDetailed(request);
  if (!execution.ok()) {
    // The rig's FAILED_PRECONDITION: too far from the surface or no drag fits.
    record.unreachable = absl::IsFailedPrecondition(execution.status());
    record.error = absl::StrCat("rig: ", execution.status().message());
    return record;
  }
  record.path = execution->path.points;
  absl::StatusOr<TraceFit> fit = FitTrace(execution->trace, options.fit);
  if (!fit.ok()) {
    record.error = absl::StrCat("fit: ", fit.status().message());
    return record;
  }
  record.fit = TextureOf(*fit);
  record.line = LineSampleOf(*fit);
  record.changes = static_cast<int>(fit->changes.size());
  record.measured = true;
  return record;
}

// Drives the sampling plan to completion with one rig.
absl::Status RunPlan(const MappingBench& bench, const MappingRunOptions& options, int finest,
                     MappingRunResult& result, std::vector<MapSample>& samples) {
  // Built as a job's are (server/plan/plan_request.h); retries and the
  // probe at their defaults, as in the service's default job.
  PlanRequest request;
  request.mode = options.mode;
  request.coarsest_level = options.coarsest_level;
  request.finest_level = finest;
  request.threshold = options.threshold;
  request.property = options.property;
  request.budget = options.sample_budget;
  request.seed = options.seed;
  request.reach = options.reach;
  SamplingPlanOptions plan_options = PlanOptionsFor(request);
  plan_options.follow_boundaries = options.follow_boundaries;
  plan_options.continuation_prior = options.continuation_prior;
  plan_options.misclassification_cost = options.misclassification_cost;
  plan_options.material_mu_risk = options.material_mu_risk;
  plan_options.small_material_weight_max = options.small_material_weight_max;
  plan_options.far_gain_expected = options.far_gain_expected;
  plan_options.issue_selected_by_gain = options.issue_selected_by_gain;
  plan_options.coarse_direction_by_gain = options.coarse_direction_by_gain;
  plan_options.boundary_cost_follows_property = options.boundary_cost_follows_property;
  plan_options.coverage_skip_share = options.coverage_skip_share;
  plan_options.quiet_coverage_skip_share = options.quiet_coverage_skip_share;
  plan_options.regions.split_against_materials = options.plan_split_against_materials;
  plan_options.regions.assign_by_texture = options.plan_assign_by_texture;
  plan_options.regions.link_materials = options.plan_link_materials;
  plan_options.regions.links = options.plan_link_options;
  std::vector<const SurfaceLevel*> levels = PlanLevels(bench.surface());
  levels.resize(finest + 1);  // the plan's finest level is its map's
  absl::StatusOr<SamplingPlan> plan = SamplingPlan::Create(levels, plan_options);
  if (!plan.ok()) return plan.status();

  while (!plan->IsComplete()) {
    std::optional<ProbeCommand> command = plan->NextCommand();
    if (!command) {
      // One rig answers every command before asking for the next, so nothing
      // is outstanding here: an incomplete plan with nothing to issue is a bug.
      return absl::InternalError("the plan is not complete but issues no command with nothing outstanding");
    }
    ProbeRecord record = MeasureSite(bench.rig(), options, command->site.vertex, command->attempt,
                                     command->position, command->normal, command->drag_direction,
                                     command->probe);
    absl::Status status;
    if (!record.measured) {
      status = plan->RecordFailure(command->sequence, record.error,
                                   record.unreachable ? FailureKind::kUnreachable : FailureKind::kTransient);
    } else if (options.mode == PlanMode::kBoundary) {
      status = plan->RecordLineSample(command->sequence, record.line);
    } else {
      status = plan->RecordFit(command->sequence, record.fit);  // one value per site, as before line samples
    }
    if (!status.ok()) {
      return absl::Status(status.code(), absl::StrCat("plan rejected the answer to command ", command->sequence,
                                                      " (vertex ", command->site.vertex, "): ", status.message()));
    }
    result.probes.push_back(std::move(record));
  }
  samples = plan->MeasuredSamples();
  result.skipped = plan->Progress().skipped;
  return absl::OkStatus();
}

// Farthest-point sampling over a level from a seeded first vertex.
std::vector<int> SpreadVertices(const SurfaceLevel& level, int count, std::uint64_t seed) {
  const int n = static_cast<int>(level.limit_positions.size());
  count = std::min(count, n);
  std::vector<int> chosen;
  if (count <= 0) return chosen;
  std::mt19937_64 rng(seed);
  chosen.push_back(std::uniform_int_distribution<int>(0, n - 1)(rng));
  std::vector<double> nearest(n, std::numeric_limits<double>::infinity());
  while (static_cast<int>(chosen.size()) < count) {
    const Eigen::Vector3d& last = level.limit_positions[chosen.back()];
    int best = -1;
    for (int v = 0; v < n; ++v) {
      nearest[v] = std::min(nearest[v], (level.limit_positions[v] - last).squaredNorm());
      if (best < 0 || nearest[v] > nearest[best]) best = v;
    }
    chosen.push_back(best);
  }
  return chosen;
}

// uniform_spread: no plan; each chosen vertex is probed up to three times.
void RunSpread(const MappingBench& bench, const MappingRunOptions& options, int finest, MappingRunResult& result,
               std::vector<MapSample>& samples) {
  const SurfaceLevel& level = bench.level(finest);
  const ProbeParameters probe;
  for (int vertex : SpreadVertices(level, options.sample_budget, options.seed)) {
    const Eigen::Vector3d& normal = level.limit_normals[vertex];
    if (UnreachableReason(options.reach, level.limit_positions[vertex], normal)) {
      ++result.skipped;
      continue;
    }
    for (int attempt = 1; attempt <= 3; ++attempt) {
      ProbeRecord record = MeasureSite(bench.rig(), options, vertex, attempt, level.limit_positions[vertex], normal,
                                       VariedDragDirection(normal, SiteShuffleKey(options.seed, vertex)), probe);
      const bool measured = record.measured, unreachable = record.unreachable;
      if (measured) samples.push_back({vertex, record.fit});
      result.probes.push_back(std::move(record));
      if (measured || unreachable) break;
    }
  }
}

MapReading ReadingOf(const MapValue& value) {
  MapReading r;
  r.mu = value.mu;
  r.has_roughness = value.has_roughness;
  if (value.has_roughness) {
    const std::vector<double> a = ReflectionToAr(value.reflection);
    r.a1 = a.size() > 0 ? a[0] : 0.0;
    r.a2 = a.size() > 1 ? a[1] : 0.0;
    r.sigma = value.sigma;
  }
  return r;
}

}  // namespace

std::string_view RunModeName(const MappingRunOptions& options) {
  return options.uniform_spread ? "uniform-spread" : PlanModeName(options.mode);
}

std::string_view MapKindName(MapKind kind) { return kind == MapKind::kRegions ? "regions" : "harmonic"; }

int MappingRunResult::measured() const {
  return static_cast<int>(std::count_if(probes.begin(), probes.end(), [](const ProbeRecord& p) { return p.measured; }));
}

bool MappingRunOptions::IsValid(std::string* why) const {
  auto fail = [why](std::string msg) {
    if (why) *why = std::move(msg);
    return false;
  };
  if (finest_level < -1 || finest_level > 6) return fail(absl::StrCat("finest_level must be in -1..6, got ", finest_level));
  if (coarsest_level < 0 || (finest_level >= 0 && coarsest_level > finest_level)) {
    return fail(absl::StrCat("coarsest_level must be in 0..finest_level (", finest_level, "), got ", coarsest_level));
  }
  if (sample_budget < 0) return fail(absl::StrCat("sample_budget must be >= 0, got ", sample_budget));
  if (uniform_spread && mode != PlanMode::kUniform) {
    return fail(absl::StrCat("uniform_spread is a uniform design; mode is ", std::string(PlanModeName(mode))));
  }
  if ((mode == PlanMode::kUncertainty || uniform_spread) && sample_budget == 0) {
    return fail(absl::StrCat(std::string(RunModeName(*this)), " mode needs a sample_budget > 0"));
  }
  if (std::string inner; !reach.IsValid(&inner)) return fail(absl::StrCat("reach: ", inner));
  if (std::string fit_why; !fit.IsValid(&fit_why)) return fail(absl::StrCat("fit: ", fit_why));
  return true;
}

absl::StatusOr<std::unique_ptr<MappingBench>> MappingBench::Create(Scene scene, std::uint64_t rig_seed,
                                                                   int rig_surface_level, int map_level,
                                                                   const SurfaceScoreOptions& score) {
  if (map_level < -1 || map_level > 6) {
    return absl::InvalidArgumentError(absl::StrCat("map level must be in 0..6, got ", map_level));
  }
  if (rig_surface_level < 0 || rig_surface_level > 6) {
    return absl::InvalidArgumentError(absl::StrCat("rig surface level must be in 0..6, got ", rig_surface_level));
  }
  std::unique_ptr<MappingBench> bench(new MappingBench());
  const double spacing_mm = DefaultSiteSpacingMm(PlanMode::kBoundary, ProbeParameters{}.segment_length_mm);
  if (map_level == -1) {
    // As the service resolves its levels (ResolveAutoLevels): from the limit
    // positions of the control mesh's level 0.
    absl::StatusOr<std::unique_ptr<LoopSurface>> coarse = DerivedPlanSurface(scene.mesh, scene.facets, 0, spacing_mm);
    if (!coarse.ok()) return coarse.status();
    map_level = *coarse ? MapLevelFor((*coarse)->level(0)) : MapLevelFor(scene.mesh);
  }
  absl::StatusOr<std::unique_ptr<LoopSurface>> plan_surface = DerivedPlanSurface(scene.mesh, scene.facets, map_level, spacing_mm);
  if (!plan_surface.ok()) return plan_surface.status();
  bench->plan_surface_ = *std::move(plan_surface);
  absl::StatusOr<SurfaceScorer> scorer = SurfaceScorer::Create(scene, score);
  if (!scorer.ok()) return scorer.status();
  SimulatedRigOptions rig_options;
  rig_options.surface_level = std::max(rig_surface_level, map_level - 1);
  rig_options.seed = rig_seed;
  absl::StatusOr<std::unique_ptr<SimulatedRig>> rig = SimulatedRig::Create(std::move(scene), rig_options);
  if (!rig.ok()) return rig.status();
  bench->rig_ = *std::move(rig);
  bench->map_level_ = map_level;
  bench->scorer_ = std::make_unique<SurfaceScorer>(*std::move(scorer));
  return bench;
}

namespace {

std::vector<MapRegionSummary> SummariseRegions(const RegionMap& map, const Scene& scene) {
  std::vector<MapRegionSummary> out(map.regions().size());
  for (std::size_t k = 0; k < out.size(); ++k) {
    const TextureRegion& region = map.regions()[k];
    MapRegionSummary& s = out[k];
    s.mu = region.statistics.mu;
    s.mu_se = region.statistics.mu_se;
    s.spread = region.statistics.spread;
    s.pieces = static_cast<int>(region.pieces.size());
    s.roughness_pieces = region.roughness_pieces;
    s.truth_mm.assign(scene.materials.size(), 0.0);
    for (int i : region.pieces) {
      const std::vector<Eigen::Vector3d>& points = map.pieces()[i].points;
      for (std::size_t j = 1; j < points.size(); ++j) {
        s.truth_mm[scene.MaterialIndexAt(0.5 * (points[j - 1] + points[j]))] += (points[j] - points[j - 1]).norm();
      }
    }
  }
  for (int r : map.region()) {
    if (r >= 0) out[r].vertex_share += 1.0 / map.vertex_count();
  }
  return out;
}

}  // namespace

absl::StatusOr<MappingRunResult> RunMapping(const MappingBench& bench, const MappingRunOptions& options) {
  if (std::string why; !options.IsValid(&why)) return absl::InvalidArgumentError(absl::StrCat("mapping run: ", why));
  const int finest = options.finest_level < 0 ? bench.plan_level() : options.finest_level;
  if (finest > bench.map_level() || options.coarsest_level > finest) {
    return absl::InvalidArgumentError(absl::StrCat("mapping run: levels ", options.coarsest_level, "..", finest,
                                                   " do not fit the bench's map level ", bench.map_level()));
  }
  const auto start = std::chrono::steady_clock::now();
  MappingRunResult result;
  result.options = options;
  std::vector<MapSample> samples;
  if (options.uniform_spread) {
    RunSpread(bench, options, finest, result, samples);
  } else if (absl::Status status = RunPlan(bench, options, finest, result, samples); !status.ok()) {
    return status;
  }
  if (samples.empty()) {
    return absl::FailedPreconditionError(
        absl::StrCat("mapping run: no site was measured (", result.probes.size(), " probes failed)"));
  }

  const SurfaceLevel& map_level = bench.map_surface();
  MapReader reader;
  std::optional<RegionMap> regions;
  std::optional<FrictionMap> harmonic;
  std::shared_ptr<const MeshLocator> harmonic_locator;
  if (options.map == MapKind::kRegions) {
    RegionMapOptions map_options;
    map_options.split_against_materials = options.map_split_against_materials;
    map_options.assign_by_texture = options.map_assign_by_texture;
    map_options.move_only_to_alike_material = options.map_move_only_to_alike_material;
    map_options.boundaries_ignore_unconfirmed_end_pieces = options.map_ignore_unconfirmed_end_pieces;
    map_options.transition_pieces_mark_one_crossing = options.map_transition_crossings;
    map_options.max_transition_piece_mm = options.map_transition_max_mm;
    map_options.known_split.test_bands = options.map_known_texture_bands;
    map_options.links = options.map_link_options;
    map_options.min_fitted_pieces_for_mu = options.map_min_fitted_pieces_for_mu;
    map_options.min_mu_piece_mm = options.map_min_mu_piece_mm;
    map_options.link_materials = options.map_link_materials;
    absl::StatusOr<RegionMap> map = RegionMap::Create(map_level, map_options);
    if (!map.ok()) return map.status();
    std::vector<MapPiece> pieces;
    for (int i = 0; i < static_cast<int>(result.probes.size()); ++i) {
      const ProbeRecord& p = result.probes[i];
      if (!p.measured) continue;
      std::vector<MapPiece> more = MapPiecesOf(p.line, i, p.position);
      pieces.insert(pieces.end(), more.begin(), more.end());
    }
    if (absl::Status status = map->SetPieces(std::move(pieces)); !status.ok()) return status;
    result.map_regions = SummariseRegions(*map, bench.scene());
    result.map_changes = static_cast<int>(map->change_marks().size());
    result.map_links = map->boundary_links();
    result.map_corners = map->boundary_corners();
    result.map_bridges = map->boundary_bridges();
    result.map_dots = map->boundary_dots();
    result.map_rectangles = map->boundary_rectangles();
    result.map_split_pieces = map->split_pieces();
    result.map_moved_regions = map->regions_moved_by_texture();
    result.map_moved_pieces = map->pieces_moved_by_texture();
    result.map_dissolved_materials = map->materials_dissolved();
    regions = std::move(*map);
    reader = [&regions](const Eigen::Vector3d& p) -> absl::StatusOr<MapReading> {
      absl::StatusOr<MapValue> v = regions->ValueAtPosition(p);
      if (!v.ok()) return v.status();
      return ReadingOf(*v);
    };
  } else {
    const SurfaceLevel& level = bench.level(finest);
    absl::StatusOr<FrictionMap> map = FrictionMap::Create(level);
    if (!map.ok()) return map.status();
    if (absl::Status status = map->SetSamples(std::move(samples)); !status.ok()) return status;
    harmonic = std::move(*map);
    harmonic_locator = std::make_shared<const MeshLocator>(level);
    reader = [&harmonic, harmonic_locator](const Eigen::Vector3d& p) -> absl::StatusOr<MapReading> {
      absl::StatusOr<MapValue> v = harmonic->ValueAt(harmonic_locator->Closest(p));
      if (!v.ok()) return v.status();
      return ReadingOf(*v);
    };
  }
  absl::StatusOr<SurfaceScore> score = bench.scorer().Score(reader);
  if (!score.ok()) return score.status();
  result.score = *std::move(score);
  for (const Eigen::Vector3d& p : map_level.limit_positions) {
    if (regions) {
      absl::StatusOr<MapValue> v = regions->ValueAtPosition(p);
      if (!v.ok()) return v.status();
      result.map_mu.push_back(v->mu);
      result.map_mu_std.push_back(v->mu_std);
    } else {
      absl::StatusOr<MapValue> v = harmonic->ValueAt(harmonic_locator->Closest(p));
      if (!v.ok()) return v.status();
      result.map_mu.push_back(v->mu);
      result.map_mu_std.push_back(v->mu_std);
    }
  }
  result.elapsed_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace surfmap::mapsim
