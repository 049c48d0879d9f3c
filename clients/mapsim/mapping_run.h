// A whole mapping run in one process, no network: the sampling plan issues
// probe commands, the simulated rig executes them on the scene, FitTrace fits
// each trace, the fit goes back to the plan, until the plan is complete; then
// the measured sites are interpolated into a friction map on the finest level.
//
// The rig is seeded per site (command id = f(vertex, attempt)), not per
// command sequence, so the same site gives the same trace in every mode: runs
// of different modes differ only in where they sample.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>
#include "absl/status/statusor.h"
#include "clients/mapsim/map_evaluation.h"
#include "clients/rig/scene.h"
#include "clients/rig/simulated_rig.h"
#include "server/estimate/fit_trace.h"
#include "server/estimate/texture.h"

namespace surfmap::mapsim {

enum class SamplingMode {
  kAdaptive,       // the paper's threshold rule (PlanMode::kAdaptive)
  kUncertainty,    // PlanMode::kUncertainty with a sample budget
  kUniformLevel,   // PlanMode::kUniform: every vertex of coarsest_level
  // `sample_budget` vertices of the finest level spread by farthest-point
  // sampling (Euclidean, from a seeded random first vertex): a uniform design
  // at any sample count, for comparisons at equal counts.
  kUniformSpread,
};
std::string_view SamplingModeName(SamplingMode mode);  // "adaptive", "uncertainty", "uniform", "uniform-spread"

struct MappingRunOptions {
  SamplingMode mode = SamplingMode::kAdaptive;
  int coarsest_level = 0;
  int finest_level = 2;          // the plan's max level and the map's level
  double threshold = 2.0;        // kAdaptive, in TextureDistance units
  TextureProperty property = TextureProperty::kFriction;  // what the texture distance compares
  int sample_budget = 0;         // 0 = unlimited (kUncertainty and kUniformSpread need one)
  std::uint64_t seed = 1;        // plan issue order, rig noise, kUniformSpread's first vertex
  FitOptions fit;

  bool IsValid(std::string* why) const;
};

// One probe as executed: where, and the path the rig dragged.
struct ProbeRecord {
  int vertex = -1;               // finest-level vertex of the site
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  std::vector<Eigen::Vector3d> path;  // forward drag path on the surface (empty when the rig failed)
  bool measured = false;         // false: the rig or FitTrace failed (see error)
  std::string error;
  TextureParams fit;
};

struct MappingRunResult {
  MappingRunOptions options;
  std::vector<ProbeRecord> probes;   // in execution order, failures included
  std::vector<double> map_mu;        // per finest-level vertex
  std::vector<double> map_mu_std;
  MapEvaluation evaluation;
  double elapsed_s = 0.0;            // the whole run: planning, simulation, fitting, the map
};

// The scene's rig and the levels a run needs, created once and shared by
// several runs (runs do not modify it).
class MappingBench {
 public:
  // The rig's surface is refined to max(rig_surface_level, finest_level)
  // (finer = smoother drag paths); the plan and the map use its levels
  // 0..finest_level. Errors: INVALID_ARGUMENT for levels outside 0..6 or a
  // scene mesh the rig rejects.
  static absl::StatusOr<std::unique_ptr<MappingBench>> Create(Scene scene, int finest_level, std::uint64_t rig_seed,
                                                              int rig_surface_level = 3);

  const SimulatedRig& rig() const { return *rig_; }
  const Scene& scene() const { return rig_->scene(); }
  int finest_level() const { return finest_level_; }
  const SurfaceLevel& finest() const { return rig_->surface().level(finest_level_); }
  const std::vector<int>& truth_material() const { return truth_material_; }  // per finest vertex

 private:
  MappingBench() = default;
  std::unique_ptr<SimulatedRig> rig_;
  int finest_level_ = 0;
  std::vector<int> truth_material_;
};

// Runs one mapping. options.finest_level must equal bench.finest_level().
// Errors: INVALID_ARGUMENT for invalid options (naming the field), errors of
// the plan or the map (e.g. no site could be measured: FAILED_PRECONDITION).
// Individual probe failures are not errors: they are recorded and reported to
// the plan (RecordFailure), which retries them.
absl::StatusOr<MappingRunResult> RunMapping(const MappingBench& bench, const MappingRunOptions& options);

}  // namespace surfmap::mapsim
