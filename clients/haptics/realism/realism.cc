#include "clients/haptics/realism/realism.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numeric>
#include <random>

#include <Eigen/Geometry>
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_join.h"
#include "server/haptics/model_drag.h"
#include "server/haptics/texture_renderer.h"
#include "clients/mapsim/mapping_run.h"
#include "clients/sim/rig/scene_truth.h"
#include "server/estimate/ar_autocorrelation.h"
#include "server/map/region_map.h"

namespace surfmap::haptics {
namespace {

constexpr double kSpeed = 10.0, kRate = 100.0, kForce = 5.0;
constexpr int kAcfLags = 10;
// Runs of one material shorter than this (samples, 0.1 mm each) are left
// out: their mean is too uncertain to detrend by.
constexpr int kMinRun = 20;
// Samples left out at each end of a run (1 mm at 0.1 mm per sample): next to
// a material change a map boundary misplaced by a millimetre puts the other
// material's friction there, which the map's boundary score already
// measures; the realism figures are about the textures inside materials.
constexpr int kRunGuard = 10;
// Cruise: the truth's ramps (half-cosine, 0.3 s) sample the texture more
// densely in arc length than the constant-speed model does; keep samples
// moving at >= 90% of the commanded speed.
constexpr double kCruiseFraction = 0.9;

// The mapped model at the bench's map level from the run's drags.
absl::StatusOr<TextureMap> ModelOf(const mapsim::MappingBench& bench, const mapsim::MappingRunResult& run) {
  absl::StatusOr<RegionMap> map = RegionMap::Create(bench.map_surface());
  if (!map.ok()) return map.status();
  std::vector<MapPiece> pieces;
  for (size_t i = 0; i < run.probes.size(); ++i) {
    if (!run.probes[i].measured) continue;
    for (MapPiece& p : MapPiecesOf(run.probes[i].line, static_cast<int>(i), run.probes[i].position)) {
      pieces.push_back(std::move(p));
    }
  }
  if (absl::Status s = map->SetPieces(std::move(pieces)); !s.ok()) return s;
  const SurfaceLevel& level = bench.map_surface();
  TextureMap out;
  out.level = bench.map_level();
  out.grid_step_mm = 0.1;  // FitOptions::step_mm of the run
  out.positions = level.limit_positions;
  out.normals = level.limit_normals;
  out.triangles = level.triangles;
  out.mu = map->mu();
  out.mu_std = map->mu_std();
  out.region = map->region();
  out.boundary_probability = map->boundary_probability();
  const int n = map->vertex_count();
  const int order = map->roughness_order();
  out.ar_order = order;
  out.reflection.assign(static_cast<size_t>(n) * order, 0.0);
  out.sigma.assign(n, 0.0);
  out.a1.assign(n, 0.0);
  out.a2.assign(n, 0.0);
  for (int v = 0; v < n; ++v) {
    if (!std::isfinite(map->log_sigma()[v])) continue;  // no roughness here
    std::vector<double> k(order);
    for (int j = 0; j < order; ++j) k[j] = map->reflection()[j][v];
    if (!std::all_of(k.begin(), k.end(), [](double x) { return std::isfinite(x); })) continue;
    out.sigma[v] = std::exp(map->log_sigma()[v]);
    for (int j = 0; j < order; ++j) out.reflection[static_cast<size_t>(v) * order + j] = k[j];
    const std::vector<double> a = ReflectionToAr(k);
    out.a1[v] = a.size() > 0 ? a[0] : 0.0;
    out.a2[v] = a.size() > 1 ? a[1] : 0.0;
  }
  for (size_t r = 0; r < map->regions().size(); ++r) {
    const surfmap::TextureRegion& src = map->regions()[r];
    haptics::TextureRegion dst;
    dst.region = static_cast<int>(r);
    dst.mu = src.statistics.mu;
    dst.mu_se = src.statistics.mu_se;
    dst.reflection = src.reflection;
    dst.ar_coefficients = ReflectionToAr(src.reflection);
    dst.sigma = src.sigma;
    dst.piece_count = static_cast<int>(src.pieces.size());
    dst.roughness_piece_count = src.roughness_pieces;
    out.regions.push_back(std::move(dst));
  }
  return out;
}

// The model with its materials swapped: every region takes the texture
// (mu, roughness) of the region whose mu is farthest from its own, so each
// place gets the map of another material (a map may split one material into
// several regions; the farthest is never one of them). Everything else,
// geometry and boundaries included, stays: only "which material is where"
// is wrong.
TextureMap SwappedModel(const TextureMap& model) {
  TextureMap wrong = model;
  const int regions = static_cast<int>(model.regions.size());
  if (regions < 2) return wrong;
  std::vector<int> swap_to(regions);
  for (int r = 0; r < regions; ++r) {
    int far = r == 0 ? 1 : 0;
    for (int q = 0; q < regions; ++q) {
      if (std::abs(model.regions[q].mu - model.regions[r].mu) > std::abs(model.regions[far].mu - model.regions[r].mu)) {
        far = q;
      }
    }
    swap_to[r] = far;
  }
  const int order = model.ar_order;
  for (int v = 0; v < model.vertex_count(); ++v) {
    const int r = model.region[v];
    if (r < 0) continue;
    const haptics::TextureRegion& to = model.regions[swap_to[r]];
    wrong.mu[v] = to.mu;
    const bool rough = to.sigma > 0 && static_cast<int>(to.reflection.size()) == order;
    wrong.sigma[v] = rough ? to.sigma : 0.0;
    for (int j = 0; j < order; ++j) wrong.reflection[static_cast<size_t>(v) * order + j] = rough ? to.reflection[j] : 0.0;
    wrong.a1[v] = rough && order > 0 ? to.ar_coefficients[0] : 0.0;
    wrong.a2[v] = rough && order > 1 ? to.ar_coefficients[1] : 0.0;
    wrong.region[v] = swap_to[r];
  }
  return wrong;
}

// Per material: the runs of force variation (N) and the friction coefficients.
struct Series {
  std::vector<std::vector<double>> runs;
  std::vector<double> mu;
};

// Splits a forward pass into runs of one true material; `cruise` says which
// samples to keep.
void Collect(const Scene& scene, const DragTrace& trace, const std::vector<bool>& cruise, std::vector<Series>& out) {
  std::vector<double> run;
  std::vector<double> run_mu;
  int material = -1;
  auto flush = [&] {
    if (static_cast<int>(run.size()) >= kMinRun + 2 * kRunGuard) {
      run.erase(run.end() - kRunGuard, run.end());
      run.erase(run.begin(), run.begin() + kRunGuard);
      run_mu.erase(run_mu.end() - kRunGuard, run_mu.end());
      run_mu.erase(run_mu.begin(), run_mu.begin() + kRunGuard);
    } else {
      run.clear();
    }
    if (material >= 0 && static_cast<int>(run.size()) >= kMinRun) {
      const double mean = std::accumulate(run.begin(), run.end(), 0.0) / run.size();
      for (double& t : run) t -= mean;
      out[material].runs.push_back(run);
      out[material].mu.insert(out[material].mu.end(), run_mu.begin(), run_mu.end());
    }
    run.clear();
    run_mu.clear();
  };
  for (size_t i = 0; i < trace.samples.size(); ++i) {
    const DragSample& s = trace.samples[i];
    if (s.phase != DragPhase::kForward) break;
    const int m = scene.MaterialIndexAt(s.position);
    if (!cruise[i] || m != material) {
      flush();
      material = cruise[i] ? m : -1;
      if (!cruise[i]) continue;
    }
    const double t = std::sqrt(std::max(0.0, s.force.squaredNorm() - kForce * kForce));
    run.push_back(t);
    run_mu.push_back(t / kForce);
  }
  flush();
}

std::vector<bool> CruiseSamples(const DragTrace& trace) {
  std::vector<bool> cruise(trace.samples.size(), false);
  for (size_t i = 1; i + 1 < trace.samples.size(); ++i) {
    const DragSample& a = trace.samples[i - 1];
    const DragSample& b = trace.samples[i + 1];
    if (trace.samples[i].phase != DragPhase::kForward || b.phase != DragPhase::kForward) continue;
    const double speed = (b.position - a.position).norm() / (b.t - a.t);
    cruise[i] = speed >= kCruiseFraction * kSpeed;
  }
  return cruise;
}

std::vector<double> Acf(const Series& s) {
  std::vector<Eigen::VectorXd> segments;
  for (const auto& run : s.runs) segments.push_back(Eigen::Map<const Eigen::VectorXd>(run.data(), run.size()));
  const Eigen::VectorXd c = PooledAutocovariance(segments, kAcfLags);
  std::vector<double> rho(kAcfLags + 1, 0.0);
  if (c.size() == 0 || !(c[0] > 0)) return rho;
  for (int k = 0; k <= kAcfLags && k < c.size(); ++k) rho[k] = c[k] / c[0];
  return rho;
}

std::vector<double> Flatten(const Series& s) {
  std::vector<double> all;
  for (const auto& run : s.runs) all.insert(all.end(), run.begin(), run.end());
  return all;
}

Figures FiguresOf(const Series& s, const Series* truth) {
  Figures f;
  if (!s.mu.empty()) f.mu = std::accumulate(s.mu.begin(), s.mu.end(), 0.0) / s.mu.size();
  const std::vector<double> all = Flatten(s);
  // Robust: 1.4826 x the median absolute deviation (= the std for normal
  // data), so the few samples where a misplaced map boundary puts the other
  // material's friction (a 1.85 N offset glass/sandpaper at 5 N) do not
  // stand in for the texture's amplitude.
  std::vector<double> dev;
  for (double x : all) dev.push_back(std::abs(x));
  if (!dev.empty()) {
    std::nth_element(dev.begin(), dev.begin() + dev.size() / 2, dev.end());
    f.rms_n = 1.4826 * dev[dev.size() / 2];
  }
  if (truth != nullptr) {
    const std::vector<double> a = Acf(s), b = Acf(*truth);
    double d = 0.0;
    for (int k = 1; k <= kAcfLags; ++k) d += (a[k] - b[k]) * (a[k] - b[k]);
    f.acf_distance = std::sqrt(d / kAcfLags);
    KolmogorovSmirnov(all, Flatten(*truth), &f.ks, &f.ks_p);
  }
  return f;
}

}  // namespace

void KolmogorovSmirnov(std::vector<double> a, std::vector<double> b, double* d, double* p) {
  *d = 0.0;
  *p = 1.0;
  if (a.empty() || b.empty()) return;
  std::sort(a.begin(), a.end());
  std::sort(b.begin(), b.end());
  size_t i = 0, j = 0;
  const double na = static_cast<double>(a.size()), nb = static_cast<double>(b.size());
  while (i < a.size() && j < b.size()) {
    const double x = std::min(a[i], b[j]);
    while (i < a.size() && a[i] <= x) ++i;
    while (j < b.size() && b[j] <= x) ++j;
    *d = std::max(*d, std::abs(i / na - j / nb));
  }
  // Kolmogorov's distribution with Stephens' small-sample correction
  // (Numerical Recipes 14.3): Q(lambda) = 2 sum (-1)^(k-1) exp(-2 k^2 lambda^2).
  const double ne = na * nb / (na + nb);
  const double lambda = (std::sqrt(ne) + 0.12 + 0.11 / std::sqrt(ne)) * *d;
  double q = 0.0, sign = 1.0;
  for (int k = 1; k <= 100; ++k) {
    const double term = sign * 2.0 * std::exp(-2.0 * k * k * lambda * lambda);
    q += term;
    sign = -sign;
    if (std::abs(term) < 1e-12) break;
  }
  *p = lambda < 0.2 ? 1.0 : std::clamp(q, 0.0, 1.0);  // the series converges slowly near 0, where Q -> 1
}

absl::StatusOr<SceneRealism> RunRealism(const std::string& scene_name, const RealismOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  absl::StatusOr<Scene> scene = LoadSceneByName(scene_name);
  if (!scene.ok()) return scene.status();
  absl::StatusOr<std::unique_ptr<mapsim::MappingBench>> bench = mapsim::MappingBench::Create(*scene, options.seed);
  if (!bench.ok()) return bench.status();
  mapsim::MappingRunOptions run_options;
  run_options.property = TextureProperty::kBoth;
  run_options.seed = options.seed;
  run_options.sample_budget = options.map_budget;
  absl::StatusOr<mapsim::MappingRunResult> run = mapsim::RunMapping(**bench, run_options);
  if (!run.ok()) return run.status();
  absl::StatusOr<TextureMap> model = ModelOf(**bench, *run);
  if (!model.ok()) return model.status();
  const TextureMap wrong_map = SwappedModel(*model);
  SceneRealism out;
  out.scene = scene_name;
  for (const haptics::TextureRegion& r : model->regions) {
    out.region_summary.push_back(absl::StrFormat("r%d mu %.3f sigma %.3f k %s (%d pieces, %d rough)", r.region, r.mu,
                                                 r.sigma, absl::StrJoin(r.reflection, ",", [](std::string* o, double k) {
                                                   absl::StrAppend(o, absl::StrFormat("%.2f", k));
                                                 }), r.piece_count, r.roughness_piece_count));
  }
  out.map_samples = run->measured();
  out.regions = static_cast<int>(model->regions.size());
  absl::StatusOr<std::unique_ptr<TextureRenderer>> renderer = TextureRenderer::Create(*model);
  if (!renderer.ok()) return renderer.status();
  absl::StatusOr<std::unique_ptr<TextureRenderer>> wrong = TextureRenderer::Create(wrong_map);
  if (!wrong.ok()) return wrong.status();

  // The truth with exact physics, on the bench's rig surface level.
  SimulatedRigOptions rig_options;
  rig_options.surface_level = (*bench)->rig().surface().max_level();
  rig_options.seed = options.seed + 1000;  // test drags are not the mapping drags
  rig_options.simulation = DragSimOptions::Ideal();
  absl::StatusOr<std::unique_ptr<SimulatedRig>> rig = SimulatedRig::Create(*scene, rig_options);
  if (!rig.ok()) return rig.status();

  // Sites stratified by true material, seeded; directions seeded.
  const SurfaceLevel& level = (*bench)->map_surface();
  const SceneTruth truth = ClassifyPoints(*scene, level.limit_positions);
  const int materials = static_cast<int>(scene->materials.size());
  std::vector<std::vector<int>> by_material(materials);
  for (size_t v = 0; v < truth.material_index.size(); ++v) by_material[truth.material_index[v]].push_back(static_cast<int>(v));
  std::mt19937_64 rng(options.seed);
  std::vector<Series> truth_series(materials), model_series(materials), wrong_series(materials);
  std::int64_t command = 1;
  ModelDragOptions drag;
  drag.speed_mm_s = kSpeed;
  drag.sample_rate_hz = kRate;
  drag.normal_force_n = kForce;
  for (int m = 0; m < materials; ++m) {
    if (by_material[m].empty()) continue;
    std::uniform_int_distribution<size_t> pick(0, by_material[m].size() - 1);
    std::uniform_real_distribution<double> angle(0.0, 2.0 * 3.141592653589793);
    int done = 0;
    for (int attempt = 0; attempt < 6 * options.drags_per_material && done < options.drags_per_material; ++attempt) {
      const int v = by_material[m][pick(rng)];
      const Eigen::Vector3d n = level.limit_normals[v];
      const Eigen::Vector3d d0 = (*rig)->surface().DefaultDragDirection(v);
      ProbeRequest request;
      request.position = level.limit_positions[v];
      request.normal = n;
      request.drag_direction = Eigen::AngleAxisd(angle(rng), n) * d0;
      request.segment_length_mm = options.drag_length_mm;
      request.speed_mm_s = kSpeed;
      request.normal_force_n = kForce;
      request.command_id = command++;
      absl::StatusOr<ProbeExecution> exec = (*rig)->ExecuteDetailed(request);
      if (!exec.ok()) continue;  // unreachable there: another site
      absl::StatusOr<ModelDrag> rendered = RenderDragAlongPath(**renderer, exec->path.points, drag);
      absl::StatusOr<ModelDrag> rendered_wrong = RenderDragAlongPath(**wrong, exec->path.points, drag);
      if (!rendered.ok() || !rendered_wrong.ok()) continue;
      Collect(*scene, exec->trace, CruiseSamples(exec->trace), truth_series);
      const std::vector<bool> all(rendered->trace.samples.size(), true);
      Collect(*scene, rendered->trace, all, model_series);
      Collect(*scene, rendered_wrong->trace, all, wrong_series);
      ++done;
      ++out.test_drags;
    }
  }
  for (int m = 0; m < materials; ++m) {
    if (truth_series[m].runs.empty()) continue;
    MaterialRealism r;
    r.material = scene->material_names[m];
    r.samples = static_cast<int>(truth_series[m].mu.size());
    r.truth = FiguresOf(truth_series[m], nullptr);
    r.model = FiguresOf(model_series[m], &truth_series[m]);
    r.wrong = FiguresOf(wrong_series[m], &truth_series[m]);
    out.materials.push_back(r);
  }
  out.elapsed_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return out;
}

std::string RealismTable(const std::vector<SceneRealism>& scenes) {
  std::string out =
      "| scene | material | n | mu truth | mu model | mu wrong | std N truth | std model | std wrong | ACF dist model "
      "| ACF dist wrong | KS D model | KS D wrong |\n"
      "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n";
  for (const SceneRealism& s : scenes) {
    for (const MaterialRealism& m : s.materials) {
      absl::StrAppend(&out, absl::StrFormat(
                                "| %s | %s | %d | %.3f | %.3f | %.3f | %.3f | %.3f | %.3f | %.3f | %.3f | %.2f | %.2f |\n",
                                s.scene, m.material, m.samples, m.truth.mu, m.model.mu, m.wrong.mu, m.truth.rms_n,
                                m.model.rms_n, m.wrong.rms_n, m.model.acf_distance, m.wrong.acf_distance, m.model.ks,
                                m.wrong.ks));
    }
  }
  return out;
}

}  // namespace surfmap::haptics
