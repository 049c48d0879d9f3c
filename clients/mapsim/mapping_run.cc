#include "clients/mapsim/mapping_run.h"

#include <chrono>
#include <limits>
#include <random>
#include <utility>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"
#include "clients/rig/scene_truth.h"
#include "server/map/friction_map.h"
#include "server/plan/drag_direction.h"
#include "server/plan/sampling_plan.h"

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
  ProbeRequest request;
  // The rig projects the (off-surface, on curved parts) start onto the surface.
  request.position = position;  // the rig centres the drag on the site
  request.normal = normal;
  request.drag_direction = drag_direction;
  request.segment_length_mm = probe.segment_length_mm;
  request.speed_mm_s = probe.speed_mm_per_s;
  request.normal_force_n = probe.normal_force_n;
  request.command_id = SiteCommandId(vertex, attempt);
  absl::StatusOr<ProbeExecution> execution = rig.ExecuteDetailed(request);
  if (!execution.ok()) {
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
  record.measured = true;
  return record;
}

PlanMode PlanModeOf(SamplingMode mode) {
  switch (mode) {
    case SamplingMode::kAdaptive:
      return PlanMode::kAdaptive;
    case SamplingMode::kUncertainty:
      return PlanMode::kUncertainty;
    case SamplingMode::kUniformLevel:
    case SamplingMode::kUniformSpread:
      return PlanMode::kUniform;
  }
  return PlanMode::kAdaptive;
}

// Drives the sampling plan to completion with one rig.
absl::Status RunPlan(const MappingBench& bench, const MappingRunOptions& options, MappingRunResult& result,
                     std::vector<MapSample>& samples) {
  SamplingPlanOptions plan_options;
  plan_options.mode = PlanModeOf(options.mode);
  plan_options.coarsest_level = options.coarsest_level;
  plan_options.max_level = options.finest_level;
  plan_options.threshold = options.threshold;
  plan_options.distance.property = options.property;
  plan_options.sample_budget = options.sample_budget;
  plan_options.seed = options.seed;
  std::vector<const SurfaceLevel*> levels = PlanLevels(bench.rig().surface());
  levels.resize(options.finest_level + 1);  // the plan's finest level is the map's
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
    absl::Status status = record.measured ? plan->RecordFit(command->sequence, record.fit)
                                          : plan->RecordFailure(command->sequence, record.error);
    if (!status.ok()) {
      return absl::Status(status.code(), absl::StrCat("plan rejected the answer to command ", command->sequence,
                                                      " (vertex ", command->site.vertex, "): ", status.message()));
    }
    result.probes.push_back(std::move(record));
  }
  samples = plan->MeasuredSamples();
  return absl::OkStatus();
}

// Farthest-point sampling over the finest level from a seeded first vertex.
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

// kUniformSpread: no plan; each chosen vertex is probed up to three times.
void RunSpread(const MappingBench& bench, const MappingRunOptions& options, MappingRunResult& result,
               std::vector<MapSample>& samples) {
  const SurfaceLevel& finest = bench.finest();
  const ProbeParameters probe;
  for (int vertex : SpreadVertices(finest, options.sample_budget, options.seed)) {
    for (int attempt = 1; attempt <= 3; ++attempt) {
      const Eigen::Vector3d& normal = finest.limit_normals[vertex];
      ProbeRecord record = MeasureSite(bench.rig(), options, vertex, attempt, finest.limit_positions[vertex],
                                       normal, TangentDragDirection(normal), probe);
      const bool measured = record.measured;
      if (measured) samples.push_back({vertex, record.fit});
      result.probes.push_back(std::move(record));
      if (measured) break;
    }
  }
}

}  // namespace

std::string_view SamplingModeName(SamplingMode mode) {
  switch (mode) {
    case SamplingMode::kAdaptive:
      return "adaptive";
    case SamplingMode::kUncertainty:
      return "uncertainty";
    case SamplingMode::kUniformLevel:
      return "uniform";
    case SamplingMode::kUniformSpread:
      return "uniform-spread";
  }
  return "adaptive";
}

bool MappingRunOptions::IsValid(std::string* why) const {
  auto fail = [why](std::string msg) {
    if (why) *why = std::move(msg);
    return false;
  };
  if (coarsest_level < 0 || coarsest_level > finest_level) {
    return fail(absl::StrCat("coarsest_level must be in 0..finest_level (", finest_level, "), got ", coarsest_level));
  }
  if (finest_level < 0 || finest_level > 6) return fail(absl::StrCat("finest_level must be in 0..6, got ", finest_level));
  if (sample_budget < 0) return fail(absl::StrCat("sample_budget must be >= 0, got ", sample_budget));
  if ((mode == SamplingMode::kUncertainty || mode == SamplingMode::kUniformSpread) && sample_budget == 0) {
    return fail(absl::StrCat(std::string(SamplingModeName(mode)), " mode needs a sample_budget > 0"));
  }
  if (std::string fit_why; !fit.IsValid(&fit_why)) return fail(absl::StrCat("fit: ", fit_why));
  return true;
}

absl::StatusOr<std::unique_ptr<MappingBench>> MappingBench::Create(Scene scene, int finest_level,
                                                                   std::uint64_t rig_seed, int rig_surface_level) {
  if (finest_level < 0 || finest_level > 6) {
    return absl::InvalidArgumentError(absl::StrCat("finest level must be in 0..6, got ", finest_level));
  }
  if (rig_surface_level < 0 || rig_surface_level > 6) {
    return absl::InvalidArgumentError(absl::StrCat("rig surface level must be in 0..6, got ", rig_surface_level));
  }
  SimulatedRigOptions rig_options;
  rig_options.surface_level = std::max(rig_surface_level, finest_level);
  rig_options.seed = rig_seed;
  absl::StatusOr<std::unique_ptr<SimulatedRig>> rig = SimulatedRig::Create(std::move(scene), rig_options);
  if (!rig.ok()) return rig.status();
  std::unique_ptr<MappingBench> bench(new MappingBench());
  bench->rig_ = *std::move(rig);
  bench->finest_level_ = finest_level;
  bench->truth_material_ =
      SceneTruthAtVertices(bench->rig_->scene(), bench->rig_->surface(), finest_level).material_index;
  return bench;
}

absl::StatusOr<MappingRunResult> RunMapping(const MappingBench& bench, const MappingRunOptions& options) {
  if (std::string why; !options.IsValid(&why)) return absl::InvalidArgumentError(absl::StrCat("mapping run: ", why));
  if (options.finest_level != bench.finest_level()) {
    return absl::InvalidArgumentError(absl::StrCat("mapping run: finest_level ", options.finest_level,
                                                   " differs from the bench's ", bench.finest_level()));
  }
  const auto start = std::chrono::steady_clock::now();
  MappingRunResult result;
  result.options = options;
  std::vector<MapSample> samples;
  if (options.mode == SamplingMode::kUniformSpread) {
    RunSpread(bench, options, result, samples);
  } else if (absl::Status status = RunPlan(bench, options, result, samples); !status.ok()) {
    return status;
  }
  if (samples.empty()) {
    return absl::FailedPreconditionError(
        absl::StrCat("mapping run: no site was measured (", result.probes.size(), " probes failed)"));
  }

  absl::StatusOr<FrictionMap> map = FrictionMap::Create(bench.finest());
  if (!map.ok()) return map.status();
  if (absl::Status status = map->SetSamples(std::move(samples)); !status.ok()) return status;
  result.map_mu = map->mu();
  result.map_mu_std = map->mu_std();

  const Scene& scene = bench.scene();
  std::vector<double> material_mus;
  for (const Material& m : scene.materials) material_mus.push_back(m.mu);
  absl::StatusOr<MapEvaluation> evaluation =
      EvaluateMap(bench.finest(), result.map_mu, bench.truth_material(), material_mus, scene.material_names);
  if (!evaluation.ok()) return evaluation.status();
  result.evaluation = *std::move(evaluation);
  result.elapsed_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace surfmap::mapsim
