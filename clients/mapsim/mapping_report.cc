#include "clients/mapsim/mapping_report.h"

#include <algorithm>
#include <cmath>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "clients/render/map_ply.h"

namespace surfmap::mapsim {
namespace {

double WorstRegion(const SurfaceScore& s) {
  double worst = 1.0;
  for (const RegionScore& r : s.regions) {
    if (r.points > 0) worst = std::min(worst, r.classified_right);
  }
  return worst;
}

}  // namespace

std::string RunLabel(const MappingRunResult& run) {
  const MappingRunOptions& o = run.options;
  std::string levels;
  switch (o.mode) {
    case PlanMode::kBoundary:
      levels = o.sample_budget > 0 ? absl::StrFormat(" n<=%d", o.sample_budget) : "";
      break;
    case PlanMode::kAdaptive:
      levels = absl::StrFormat(" L%d-%d t=%g", o.coarsest_level, o.finest_level, o.threshold);
      break;
    case PlanMode::kUncertainty:
      levels = absl::StrFormat(" n<=%d", o.sample_budget);
      break;
    case PlanMode::kUniform:
      levels = o.uniform_spread ? absl::StrFormat(" n=%d", o.sample_budget) : absl::StrFormat(" L%d", o.coarsest_level);
      break;
  }
  return absl::StrCat(std::string(RunModeName(o)), levels, "/", std::string(MapKindName(o.map)));
}

std::string FormatRunTable(const std::string& scene, int control_vertices, const std::vector<MappingRunResult>& runs) {
  std::string out = absl::StrFormat("%-13s %-34s %7s %7s %7s %8s %8s %8s %8s %6s\n", "scene", "run", "samples",
                                    "/ CVs", "right%", "worst%", "mu RMSE", "bnd mm", "miss mm", "time s");
  for (const MappingRunResult& run : runs) {
    const SurfaceScore& s = run.score;
    absl::StrAppendFormat(&out, "%-13s %-34s %7d %7.2f %7.2f %8.2f %8.4f %8.2f %8.2f %6.2f\n", scene, RunLabel(run),
                          run.measured(), static_cast<double>(run.measured()) / control_vertices,
                          100.0 * s.classified_right, 100.0 * WorstRegion(s), s.mu_rmse, s.boundary_error_mm,
                          s.missed_boundary_mm, run.elapsed_s);
  }
  return out;
}

std::string FormatMapRegions(const MappingRunResult& run, const Scene& scene) {
  if (run.map_regions.empty()) return "";
  std::string out = absl::StrFormat("  %-8s %6s %7s %6s %12s %6s  %s\n", "map", "mu", "se", "spread", "pieces (R)",
                                    "map%", "truth under its pieces (by length)");
  for (std::size_t k = 0; k < run.map_regions.size(); ++k) {
    const MapRegionSummary& r = run.map_regions[k];
    double total = 0.0;
    for (double mm : r.truth_mm) total += mm;
    std::vector<std::pair<double, int>> by_length;
    for (std::size_t m = 0; m < r.truth_mm.size(); ++m) {
      if (r.truth_mm[m] > 0.0) by_length.emplace_back(-r.truth_mm[m], static_cast<int>(m));
    }
    std::sort(by_length.begin(), by_length.end());
    std::string truth;
    for (const auto& [minus_mm, m] : by_length) {
      absl::StrAppendFormat(&truth, "%s%s %.0f %%", truth.empty() ? "" : ", ", scene.material_names[m],
                            total > 0.0 ? -100.0 * minus_mm / total : 0.0);
    }
    absl::StrAppendFormat(&out, "  %-8s %6.3f %7.4f %6.3f %7d (%2d) %6.1f  %s\n", absl::StrCat("[", k, "]"), r.mu,
                          r.mu_se, r.spread, r.pieces, r.roughness_pieces, 100.0 * r.vertex_share,
                          truth.empty() ? "-" : truth);
  }
  absl::StrAppendFormat(&out,
                        "  boundaries: %d crossings between regions, %d links, %d corners, %d dots' circles and %d "
                        "rectangles drawn through them, %d carried across a change beyond them\n",
                        run.map_changes, run.map_links, run.map_corners, run.map_dots, run.map_rectangles,
                        run.map_bridges);
  absl::StrAppendFormat(&out, "  pieces split against the materials' textures: %d\n", run.map_split_pieces);
  absl::StrAppendFormat(&out, "  regions moved to the material whose texture fits them: %d\n", run.map_moved_regions);
  absl::StrAppendFormat(&out, "  pieces moved out of their region to the material whose texture fits them: %d\n",
                        run.map_moved_pieces);
  absl::StrAppendFormat(&out, "  materials dissolved as mixtures of two others: %d\n", run.map_dissolved_materials);
  return out;
}

nlohmann::json RunToJson(const MappingRunResult& run) {
  const MappingRunOptions& o = run.options;
  nlohmann::json probes = nlohmann::json::array();
  for (const ProbeRecord& p : run.probes) {
    nlohmann::json j = {{"vertex", p.vertex},
                        {"position", {p.position.x(), p.position.y(), p.position.z()}},
                        {"direction", {p.direction.x(), p.direction.y(), p.direction.z()}},
                        {"measured", p.measured}};
    if (p.measured) {
      j["mu"] = p.fit.mu;
      j["changes"] = p.changes;
      nlohmann::json pieces = nlohmann::json::array();
      for (const LinePiece& piece : p.line.pieces) {
        pieces.push_back({{"from_mm", piece.start_mm},
                          {"to_mm", piece.end_mm},
                          {"mu", piece.texture.mu},
                          {"mu_se", piece.mu_se},
                          {"spread", piece.texture.mu_std},
                          {"roughness", piece.has_roughness()}});
        if (piece.has_roughness()) {
          pieces.back()["reflection"] = piece.texture.reflection;
          pieces.back()["sigma"] = piece.texture.sigma;
        }
      }
      j["pieces"] = std::move(pieces);
      // The executed path, so a reader can tell which drags crossed which
      // feature (pieces' from/to are arc lengths along the window of it).
      nlohmann::json path = nlohmann::json::array();
      for (const Eigen::Vector3d& q : p.path) path.push_back({q.x(), q.y(), q.z()});
      j["path"] = std::move(path);
    } else {
      j["error"] = p.error;
      j["unreachable"] = p.unreachable;
    }
    probes.push_back(std::move(j));
  }
  return {{"run", RunLabel(run)},
          {"mode", RunModeName(o)},
          {"map", MapKindName(o.map)},
          {"coarsest_level", o.coarsest_level},
          {"finest_level", o.finest_level},
          {"threshold", o.threshold},
          {"sample_budget", o.sample_budget},
          {"seed", o.seed},
          {"samples", run.measured()},
          {"failed_probes", static_cast<int>(run.probes.size()) - run.measured()},
          {"skipped_sites", run.skipped},
          {"elapsed_s", run.elapsed_s},
          {"score", SurfaceScoreToJson(run.score)},
          {"probes", std::move(probes)}};
}

MapMesh RunMapMesh(const MappingBench& bench, const MappingRunResult& run) {
  const SurfaceLevel& finest = bench.map_surface();
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
  for (const Eigen::Vector3d& p : bench.map_surface().limit_positions) {
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
  options.comment = absl::StrFormat("surfmap-mapsim scene %s run %s seed %d", bench.scene().name, RunLabel(run),
                                    run.options.seed);
  const MapRenderOptions render = SceneRenderOptions(bench);
  options.value_min = render.value_min;
  options.value_max = render.value_max;
  return WriteMapPly(RunMapMesh(bench, run), options);
}

}  // namespace surfmap::mapsim
