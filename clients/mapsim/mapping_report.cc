#include "clients/mapsim/mapping_report.h"

#include <algorithm>
#include <cmath>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "clients/render/map_ply.h"

namespace surfmap::mapsim {
namespace {

int Measured(const MappingRunResult& run) {
  return static_cast<int>(std::count_if(run.probes.begin(), run.probes.end(),
                                        [](const ProbeRecord& p) { return p.measured; }));
}

std::string LevelsLabel(const MappingRunResult& run) {
  const MappingRunOptions& o = run.options;
  switch (o.mode) {
    case SamplingMode::kAdaptive:
      return absl::StrFormat("L%d-%d t=%.2g", o.coarsest_level, o.finest_level, o.threshold);
    case SamplingMode::kUncertainty:
      return absl::StrFormat("L%d-%d n<=%d", o.coarsest_level, o.finest_level, o.sample_budget);
    case SamplingMode::kUniformLevel:
      return absl::StrFormat("L%d", o.coarsest_level);
    case SamplingMode::kUniformSpread:
      return absl::StrFormat("L%d fps n=%d", o.finest_level, o.sample_budget);
  }
  return "";
}

}  // namespace

std::string FormatComparisonTable(const std::vector<MappingRunResult>& runs) {
  std::string out = absl::StrFormat("%-15s %-15s %7s %5s %8s %8s %8s %9s %9s %7s\n", "mode", "levels", "samples",
                                    "fail", "mu RMSE", "max err", "class %", "bnd mm", "spur mm", "time s");
  for (const MappingRunResult& run : runs) {
    const MapEvaluation& e = run.evaluation;
    absl::StrAppendFormat(&out, "%-15s %-15s %7d %5d %8.4f %8.4f %8.2f %9.2f %9.2f %7.2f\n",
                          SamplingModeName(run.options.mode), LevelsLabel(run), Measured(run),
                          static_cast<int>(run.probes.size()) - Measured(run), e.mu_rmse, e.mu_max_abs_error,
                          100.0 * e.classification_accuracy, e.boundary_error_mm, e.spurious_boundary_mm,
                          run.elapsed_s);
  }
  if (runs.empty()) return out;
  absl::StrAppend(&out, "\nmean map mu per true material (truth mu, vertices):\n");
  absl::StrAppendFormat(&out, "%-15s", "mode");
  for (const MaterialEvaluation& m : runs.front().evaluation.materials) {
    absl::StrAppendFormat(&out, " %22s", absl::StrFormat("%s %.3f (%d)", m.name, m.truth_mu, m.vertices));
  }
  absl::StrAppend(&out, "\n");
  for (const MappingRunResult& run : runs) {
    absl::StrAppendFormat(&out, "%-15s", SamplingModeName(run.options.mode));
    for (const MaterialEvaluation& m : run.evaluation.materials) {
      absl::StrAppendFormat(&out, " %22s", absl::StrFormat("%.4f", m.map_mu_mean));
    }
    absl::StrAppend(&out, "\n");
  }
  return out;
}

nlohmann::json RunToJson(const MappingRunResult& run) {
  const MappingRunOptions& o = run.options;
  const MapEvaluation& e = run.evaluation;
  // JSON has no NaN: an undefined number is written as null.
  auto number = [](double x) -> nlohmann::json { return std::isfinite(x) ? nlohmann::json(x) : nlohmann::json(); };
  nlohmann::json materials = nlohmann::json::array();
  for (const MaterialEvaluation& m : e.materials) {
    materials.push_back({{"name", m.name},
                         {"truth_mu", m.truth_mu},
                         {"vertices", m.vertices},
                         {"map_mu_mean", number(m.map_mu_mean)},
                         {"map_mu_rmse", number(m.map_mu_rmse)}});
  }
  nlohmann::json probes = nlohmann::json::array();
  for (const ProbeRecord& p : run.probes) {
    nlohmann::json j = {{"vertex", p.vertex},
                        {"position", {p.position.x(), p.position.y(), p.position.z()}},
                        {"measured", p.measured}};
    if (p.measured) {
      j["mu"] = p.fit.mu;
      j["mu_std"] = p.fit.mu_std;
      j["sigma"] = p.fit.sigma;
      j["reflection"] = p.fit.reflection;
    } else {
      j["error"] = p.error;
    }
    probes.push_back(std::move(j));
  }
  return {{"mode", SamplingModeName(o.mode)},
          {"coarsest_level", o.coarsest_level},
          {"finest_level", o.finest_level},
          {"threshold", o.threshold},
          {"sample_budget", o.sample_budget},
          {"seed", o.seed},
          {"samples", Measured(run)},
          {"failed_probes", static_cast<int>(run.probes.size()) - Measured(run)},
          {"elapsed_s", run.elapsed_s},
          {"vertices", e.vertices},
          {"mu_rmse", number(e.mu_rmse)},
          {"mu_max_abs_error", number(e.mu_max_abs_error)},
          {"classification_accuracy", number(e.classification_accuracy)},
          {"truth_boundary_vertices", e.truth_boundary_vertices},
          {"map_boundary_vertices", e.map_boundary_vertices},
          {"boundary_error_mm", number(e.boundary_error_mm)},
          {"spurious_boundary_mm", number(e.spurious_boundary_mm)},
          {"materials", std::move(materials)},
          {"probes", std::move(probes)}};
}

MapMesh RunMapMesh(const MappingBench& bench, const MappingRunResult& run) {
  const SurfaceLevel& finest = bench.finest();
  MapMesh mesh;
  mesh.positions = finest.limit_positions;
  mesh.normals = finest.limit_normals;
  mesh.triangles = finest.triangles;
  mesh.values = run.map_mu;
  mesh.uncertainties = run.map_mu_std;
  return mesh;
}

MapOverlay RunOverlay(const MappingRunResult& run) {
  MapOverlay overlay;
  for (const ProbeRecord& p : run.probes) {
    if (!p.measured) continue;
    overlay.sample_points.push_back(p.position);
    if (p.path.size() >= 2) overlay.drag_paths.push_back(p.path);
  }
  return overlay;
}

MapRenderOptions SceneRenderOptions(const MappingBench& bench) {
  MapRenderOptions options;
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e300), hi = Eigen::Vector3d::Constant(-1e300);
  for (const Eigen::Vector3d& p : bench.finest().limit_positions) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  const Eigen::Vector3d extent = hi - lo;
  if (extent.z() < 0.05 * extent.maxCoeff()) {  // flat in z: look down on it
    options.view_direction = Eigen::Vector3d(0, 0, -1);
    options.up = Eigen::Vector3d::UnitY();
    options.two_views = false;
    options.view_width = 640;
  } else {  // standing object: the +x side, then the -x side
    options.view_direction = Eigen::Vector3d(-1, 0, 0);
    options.up = Eigen::Vector3d::UnitZ();
    options.two_views = true;
  }
  double mu_lo = 1e300, mu_hi = -1e300;
  for (const Material& m : bench.scene().materials) {
    mu_lo = std::min(mu_lo, m.mu);
    mu_hi = std::max(mu_hi, m.mu);
  }
  if (mu_hi > mu_lo) {
    options.value_min = mu_lo;
    options.value_max = mu_hi;
  }
  options.color_map = ColorMap::kGrey;
  options.dot_radius_px = 2.5;
  options.line_width_px = 1;
  return options;
}

absl::StatusOr<std::string> RunPng(const MappingBench& bench, const MappingRunResult& run) {
  return RenderMapPng(RunMapMesh(bench, run), RunOverlay(run), SceneRenderOptions(bench));
}

absl::StatusOr<std::string> RunPly(const MappingBench& bench, const MappingRunResult& run) {
  MapPlyOptions options;
  options.comment = absl::StrFormat("surfmap-mapsim scene %s mode %s levels %d-%d threshold %g seed %d",
                                    bench.scene().name, SamplingModeName(run.options.mode),
                                    run.options.coarsest_level, run.options.finest_level, run.options.threshold,
                                    run.options.seed);
  const MapRenderOptions render = SceneRenderOptions(bench);
  options.value_min = render.value_min;
  options.value_max = render.value_max;
  return WriteMapPly(RunMapMesh(bench, run), options);
}

}  // namespace surfmap::mapsim
