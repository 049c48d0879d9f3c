#include "clients/sim/rig/surface_score.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

#include <Eigen/Geometry>
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "clients/sim/rig/scene_surface.h"
#include "server/mesh/loop_surface.h"

namespace surfmap {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

double Median(std::vector<double> v) {
  if (v.empty()) return kNaN;
  const std::size_t n = v.size();
  std::nth_element(v.begin(), v.begin() + n / 2, v.end());
  double m = v[n / 2];
  if (n % 2 == 0) m = 0.5 * (m + *std::max_element(v.begin(), v.begin() + n / 2));
  return m;
}

// Distance from each of `from` to the nearest of `to` (+inf when `to` is
// empty). A uniform grid over `to` with cells of `cell` mm, searched in
// growing shells until the best distance is certain.
std::vector<double> NearestDistances(const std::vector<Eigen::Vector3d>& from, const std::vector<Eigen::Vector3d>& to,
                                     double cell) {
  std::vector<double> out(from.size(), std::numeric_limits<double>::infinity());
  if (to.empty()) return out;
  Eigen::Vector3d lo = to.front(), hi = lo;
  for (const auto& p : to) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
  const Eigen::Vector3i dims = (((hi - lo) / cell).array().floor().cast<int>() + 1).matrix();
  auto cell_of = [&](const Eigen::Vector3d& p) {
    Eigen::Vector3i c = ((p - lo) / cell).array().floor().cast<int>().matrix();
    return c;
  };
  std::vector<std::vector<int>> grid(static_cast<std::size_t>(dims.x()) * dims.y() * dims.z());
  auto index = [&](const Eigen::Vector3i& c) { return (static_cast<std::size_t>(c.z()) * dims.y() + c.y()) * dims.x() + c.x(); };
  for (int i = 0; i < static_cast<int>(to.size()); ++i) grid[index(cell_of(to[i]))].push_back(i);
  const int max_shell = dims.maxCoeff();
  for (std::size_t q = 0; q < from.size(); ++q) {
    const Eigen::Vector3i c = cell_of(from[q]);
    double best2 = std::numeric_limits<double>::infinity();
    for (int shell = 0; shell <= max_shell + std::max(0, (c.cwiseAbs()).maxCoeff()); ++shell) {
      // Every point in shells beyond this one is at least (shell - 1) cells away.
      const double reach = std::max(0, shell - 1) * cell;
      if (reach * reach > best2) break;
      for (int z = c.z() - shell; z <= c.z() + shell; ++z) {
        if (z < 0 || z >= dims.z()) continue;
        for (int y = c.y() - shell; y <= c.y() + shell; ++y) {
          if (y < 0 || y >= dims.y()) continue;
          for (int x = c.x() - shell; x <= c.x() + shell; ++x) {
            if (x < 0 || x >= dims.x()) continue;
            if (std::max({std::abs(x - c.x()), std::abs(y - c.y()), std::abs(z - c.z())}) != shell) continue;
            for (int i : grid[index({x, y, z})]) best2 = std::min(best2, (to[i] - from[q]).squaredNorm());
          }
        }
      }
    }
    out[q] = std::sqrt(best2);
  }
  return out;
}

double Mean(const std::vector<double>& v) {
  if (v.empty()) return kNaN;
  double s = 0.0;
  for (double x : v) s += x;
  return s / static_cast<double>(v.size());
}

double Percentile(std::vector<double> v, double q) {
  if (v.empty()) return kNaN;
  const std::size_t k = std::min(v.size() - 1, static_cast<std::size_t>(q * static_cast<double>(v.size())));
  std::nth_element(v.begin(), v.begin() + k, v.end());
  return v[k];
}

nlohmann::json Number(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); }

}  // namespace

bool SurfaceScoreOptions::IsValid(std::string* why) const {
  auto fail = [why](std::string m) {
    if (why != nullptr) *why = std::move(m);
    return false;
  };
  if (points < 1) return fail(absl::StrCat("points ", points, " must be >= 1"));
  if (min_region_points < 0) return fail(absl::StrCat("min_region_points ", min_region_points, " must be >= 0"));
  if (max_region_draws_per_point < 0 || max_region_draws_per_point > 10000) {
    return fail(absl::StrCat("max_region_draws_per_point ", max_region_draws_per_point, " is not in 0..10000"));
  }
  if (truth_level < 1 || truth_level > 6) return fail(absl::StrCat("truth_level ", truth_level, " is not in 1..6"));
  if (boundary_bisections < 0 || boundary_bisections > 30) {
    return fail(absl::StrCat("boundary_bisections ", boundary_bisections, " is not in 0..30"));
  }
  if (!(rough_min_process_std_n >= 0.0)) return fail("rough_min_process_std_n must be >= 0");
  return true;
}

absl::StatusOr<SurfaceScorer> SurfaceScorer::Create(const Scene& scene, const SurfaceScoreOptions& options) {
  std::string why;
  if (!options.IsValid(&why)) return absl::InvalidArgumentError(absl::StrCat("surface score options: ", why));
  if (scene.materials.empty()) return absl::InvalidArgumentError(absl::StrCat("scene '", scene.name, "' has no materials"));
  absl::StatusOr<std::unique_ptr<LoopSurface>> surface = SceneSurface(scene, options.truth_level);
  if (!surface.ok()) return surface.status();
  SurfaceScorer scorer;
  scorer.scene_ = scene;
  scorer.options_ = options;
  const SurfaceLevel& level = (*surface)->finest();
  scorer.vertices_ = level.limit_positions;
  scorer.edges_ = level.edges;
  for (const auto& p : scorer.vertices_) scorer.vertex_material_.push_back(scene.MaterialIndexAt(p));

  // Area-weighted points: a triangle by cumulative area, then a uniform point in it.
  std::vector<double> cumulative;
  double total = 0.0;
  for (const auto& t : level.triangles) {
    const auto& p = level.limit_positions;
    total += 0.5 * (p[t[1]] - p[t[0]]).cross(p[t[2]] - p[t[0]]).norm();
    cumulative.push_back(total);
  }
  std::mt19937_64 rng(options.seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  auto draw = [&]() {
    const double r = unit(rng) * total;
    const std::size_t t = std::min<std::size_t>(std::upper_bound(cumulative.begin(), cumulative.end(), r) - cumulative.begin(),
                                                cumulative.size() - 1);
    const double u = std::sqrt(unit(rng)), v = unit(rng);
    const auto& tri = level.triangles[t];
    const auto& p = level.limit_positions;
    return Eigen::Vector3d((1.0 - u) * p[tri[0]] + u * (1.0 - v) * p[tri[1]] + u * v * p[tri[2]]);
  };
  auto region_of = [&](const Eigen::Vector3d& point) {
    for (std::size_t k = 0; k < scene.regions.size(); ++k) {
      if (scene.regions[k].Contains(point)) return static_cast<int>(k);
    }
    return -1;
  };
  auto keep = [&](const Eigen::Vector3d& point, int region) {
    scorer.points_.push_back(point);
    scorer.point_region_.push_back(region);
    scorer.point_material_.push_back(region < 0 ? scene.default_material : scene.regions[region].material);
  };
  const int slots = static_cast<int>(scene.regions.size()) + 1;  // the regions, then the default material
  auto slot_of = [&](int region) { return region < 0 ? slots - 1 : region; };
  std::vector<int> in_slot(slots, 0);
  for (int i = 0; i < options.points; ++i) {
    const Eigen::Vector3d point = draw();
    const int region = region_of(point);
    keep(point, region);
    ++in_slot[slot_of(region)];
  }
  scorer.uniform_points_ = options.points;
  // Regions the sample left thin, topped up from the same distribution.
  // A region no uniform point fell in is topped up too, when the draws find it.
  const auto short_of_points = [&](int slot) { return in_slot[slot] < options.min_region_points; };
  int thin = 0;
  for (int k = 0; k < slots; ++k) thin += short_of_points(k);
  const int64_t max_draws = static_cast<int64_t>(options.max_region_draws_per_point) * options.points;
  for (int64_t d = 0; thin > 0 && d < max_draws; ++d) {
    const Eigen::Vector3d point = draw();
    const int region = region_of(point);
    const int slot = slot_of(region);
    if (!short_of_points(slot)) continue;
    keep(point, region);
    if (++in_slot[slot] == options.min_region_points) --thin;
  }

  // True boundary points: bisection of the edges whose ends differ.
  for (const auto& e : scorer.edges_) {
    int ma = scorer.vertex_material_[e[0]];
    if (ma == scorer.vertex_material_[e[1]]) continue;
    Eigen::Vector3d a = scorer.vertices_[e[0]], b = scorer.vertices_[e[1]];
    for (int k = 0; k < options.boundary_bisections; ++k) {
      const Eigen::Vector3d m = 0.5 * (a + b);
      (scene.MaterialIndexAt(m) == ma ? a : b) = m;
    }
    scorer.truth_boundary_.push_back(0.5 * (a + b));
  }
  return scorer;
}

int SurfaceScorer::NearestMaterial(double mu) const {
  int best = 0;
  for (int m = 1; m < static_cast<int>(scene_.materials.size()); ++m) {
    if (std::abs(scene_.materials[m].mu - mu) < std::abs(scene_.materials[best].mu - mu)) best = m;
  }
  return best;
}

absl::StatusOr<SurfaceScore> SurfaceScorer::Score(const MapReader& map) const {
  auto read = [&](const Eigen::Vector3d& p) -> absl::StatusOr<MapReading> {
    absl::StatusOr<MapReading> r = map(p);
    if (!r.ok()) {
      return absl::Status(r.status().code(), absl::StrFormat("map at (%.3f, %.3f, %.3f): %s", p.x(), p.y(), p.z(),
                                                             r.status().message()));
    }
    if (!std::isfinite(r->mu)) {
      return absl::InvalidArgumentError(absl::StrFormat("map at (%.3f, %.3f, %.3f): mu is %g", p.x(), p.y(), p.z(), r->mu));
    }
    return r;
  };

  SurfaceScore score;
  score.points = uniform_points_;
  const int region_count = static_cast<int>(scene_.regions.size());
  score.regions.resize(region_count + 1);
  for (int r = 0; r <= region_count; ++r) {
    RegionScore& rs = score.regions[r];
    const int m = r < region_count ? scene_.regions[r].material : scene_.default_material;
    const Material& material = scene_.materials[m];
    rs.material = scene_.material_names[m];
    rs.name = r < region_count ? absl::StrCat(rs.material, " (regions[", r, "])") : rs.material + " (default)";
    rs.truth_mu = material.mu;
    rs.rough = std::sqrt(ArProcessVariance(material)) >= options_.rough_min_process_std_n;
    rs.truth_a1 = material.a1;
    rs.truth_a2 = material.a2;
    rs.truth_sigma = material.sigma;
  }
  std::vector<int> right(region_count + 1, 0);
  std::vector<double> sum(region_count + 1, 0.0), sum_sq(region_count + 1, 0.0);
  std::vector<std::vector<double>> a1(region_count + 1), a2(region_count + 1), sigma(region_count + 1);
  std::vector<MisclassifiedPoint> misclassified, misclassified_region_only;
  double total_sq = 0.0;
  int total_right = 0;
  for (std::size_t i = 0; i < points_.size(); ++i) {
    absl::StatusOr<MapReading> r = read(points_[i]);
    if (!r.ok()) return r.status();
    const int slot = point_region_[i] < 0 ? region_count : point_region_[i];
    const int m = point_material_[i];
    const double error = r->mu - scene_.materials[m].mu;
    const bool uniform = static_cast<int>(i) < uniform_points_;
    RegionScore& rs = score.regions[slot];
    ++rs.points;
    rs.extra_points += !uniform;
    sum[slot] += r->mu;
    sum_sq[slot] += error * error;
    const bool is_right = NearestMaterial(r->mu) == m;
    right[slot] += is_right;
    if (!is_right) {
      (uniform ? misclassified : misclassified_region_only)
          .push_back({points_[i], m, point_region_[i], !uniform, r->mu, 0.0});
    }
    if (uniform) {
      total_sq += error * error;
      score.mu_max_abs_error = std::max(score.mu_max_abs_error, std::abs(error));
      total_right += is_right;
    }
    if (r->has_roughness) {
      a1[slot].push_back(r->a1);
      a2[slot].push_back(r->a2);
      sigma[slot].push_back(r->sigma);
    }
  }
  score.classified_right = static_cast<double>(total_right) / score.points;
  score.mu_rmse = std::sqrt(total_sq / score.points);
  for (int r = 0; r <= region_count; ++r) {
    RegionScore& rs = score.regions[r];
    rs.classified_right = rs.points ? static_cast<double>(right[r]) / rs.points : kNaN;
    rs.map_mu_mean = rs.points ? sum[r] / rs.points : kNaN;
    rs.map_mu_rmse = rs.points ? std::sqrt(sum_sq[r] / rs.points) : kNaN;
    rs.points_with_roughness = static_cast<int>(a1[r].size());
    rs.a1_median = Median(a1[r]);
    rs.a2_median = Median(a2[r]);
    rs.sigma_median = Median(sigma[r]);
  }

  // The map's boundaries on the dense level's edges.
  std::vector<int> vertex_class(vertices_.size());
  for (std::size_t v = 0; v < vertices_.size(); ++v) {
    absl::StatusOr<MapReading> r = read(vertices_[v]);
    if (!r.ok()) return r.status();
    vertex_class[v] = NearestMaterial(r->mu);
  }
  std::vector<Eigen::Vector3d> map_boundary;
  for (const auto& e : edges_) {
    const int ca = vertex_class[e[0]];
    if (ca == vertex_class[e[1]]) continue;
    Eigen::Vector3d a = vertices_[e[0]], b = vertices_[e[1]];
    for (int k = 0; k < options_.boundary_bisections; ++k) {
      const Eigen::Vector3d m = 0.5 * (a + b);
      absl::StatusOr<MapReading> r = read(m);
      if (!r.ok()) return r.status();
      (NearestMaterial(r->mu) == ca ? a : b) = m;
    }
    map_boundary.push_back(0.5 * (a + b));
  }
  score.truth_boundary_points = static_cast<int>(truth_boundary_.size());
  score.map_boundary_points = static_cast<int>(map_boundary.size());
  // Grid cells of 4 mm: a few boundary points each on the built-in scenes.
  constexpr double kCellMm = 4.0;
  if (!truth_boundary_.empty() && !map_boundary.empty()) {
    const std::vector<double> placed = NearestDistances(map_boundary, truth_boundary_, kCellMm);
    score.boundary_error_mm = Mean(placed);
    score.boundary_error_p90_mm = Percentile(placed, 0.9);
    score.missed_boundary_mm = Mean(NearestDistances(truth_boundary_, map_boundary, kCellMm));
  } else {
    score.boundary_error_mm = score.boundary_error_p90_mm = score.missed_boundary_mm = kNaN;
  }
  // The random points first, then the region-only ones; the mean distance
  // is the random points' alone.
  score.misclassified = std::move(misclassified);
  const std::size_t random_wrong = score.misclassified.size();
  score.misclassified.insert(score.misclassified.end(), misclassified_region_only.begin(),
                             misclassified_region_only.end());
  std::vector<Eigen::Vector3d> wrong_points;
  for (const MisclassifiedPoint& p : score.misclassified) wrong_points.push_back(p.position);
  const std::vector<double> wrong_distance = NearestDistances(wrong_points, truth_boundary_, kCellMm);
  for (std::size_t i = 0; i < wrong_distance.size(); ++i) {
    score.misclassified[i].boundary_distance_mm = wrong_distance[i];
  }
  score.misclassified_distance_mm =
      truth_boundary_.empty() || random_wrong == 0
          ? kNaN
          : Mean(std::vector<double>(wrong_distance.begin(), wrong_distance.begin() + random_wrong));
  return score;
}

std::string FormatSurfaceScore(const SurfaceScore& s, const std::string& title) {
  int extra = 0;
  for (const RegionScore& r : s.regions) extra += r.extra_points;
  std::string out = absl::StrFormat("%s: %d points on the true surface", title, s.points);
  if (extra > 0) absl::StrAppendFormat(&out, " (+%d inside small regions, for their rows only)", extra);
  out += "\n";
  absl::StrAppendFormat(&out, "  classified right %.2f %%, mu RMSE %.4f (max |error| %.3f)\n", 100.0 * s.classified_right,
                        s.mu_rmse, s.mu_max_abs_error);
  absl::StrAppendFormat(&out,
                        "  boundaries: map -> truth %.2f mm (p90 %.2f), truth -> map %.2f mm; misclassified points lie "
                        "%.2f mm from a true boundary on average\n",
                        s.boundary_error_mm, s.boundary_error_p90_mm, s.missed_boundary_mm, s.misclassified_distance_mm);
  absl::StrAppendFormat(&out, "  %-24s %7s %7s %7s %7s %7s   %-28s %s\n", "region", "points", "right%", "truth", "map mu",
                        "rmse", "a1 / a2 / sigma (median)", "truth");
  for (const RegionScore& r : s.regions) {
    if (r.points == 0) continue;
    std::string rough = "-";
    std::string truth = "-";
    if (r.rough) {
      rough = r.points_with_roughness ? absl::StrFormat("%.2f / %.2f / %.3f (%d)", r.a1_median, r.a2_median,
                                                        r.sigma_median, r.points_with_roughness)
                                      : "none";
      truth = absl::StrFormat("%.2f / %.2f / %.3f", r.truth_a1, r.truth_a2, r.truth_sigma);
    }
    absl::StrAppendFormat(&out, "  %-24s %7d %7.2f %7.3f %7.3f %7.4f   %-28s %s\n", r.name, r.points,
                          100.0 * r.classified_right, r.truth_mu, r.map_mu_mean, r.map_mu_rmse, rough, truth);
  }
  return out;
}

nlohmann::json SurfaceScoreToJson(const SurfaceScore& s) {
  nlohmann::json regions = nlohmann::json::array();
  for (const RegionScore& r : s.regions) {
    nlohmann::json j = {{"name", r.name},
                        {"material", r.material},
                        {"truth_mu", r.truth_mu},
                        {"points", r.points},
                        {"extra_points", r.extra_points},
                        {"classified_right", Number(r.classified_right)},
                        {"map_mu_mean", Number(r.map_mu_mean)},
                        {"map_mu_rmse", Number(r.map_mu_rmse)},
                        {"rough", r.rough}};
    if (r.rough) {
      j["truth_roughness"] = {{"a1", r.truth_a1}, {"a2", r.truth_a2}, {"sigma", r.truth_sigma}};
      j["points_with_roughness"] = r.points_with_roughness;
      j["roughness_median"] = {{"a1", Number(r.a1_median)}, {"a2", Number(r.a2_median)}, {"sigma", Number(r.sigma_median)}};
    }
    regions.push_back(std::move(j));
  }
  nlohmann::json misclassified = nlohmann::json::array();
  for (const MisclassifiedPoint& p : s.misclassified) {
    misclassified.push_back({{"position", {p.position.x(), p.position.y(), p.position.z()}},
                             {"truth_material", p.truth_material},
                             {"region", p.region},
                             {"region_only", p.region_only},
                             {"map_mu", p.map_mu},
                             {"boundary_distance_mm", Number(p.boundary_distance_mm)}});
  }
  return {{"points", s.points},
          {"classified_right", Number(s.classified_right)},
          {"mu_rmse", Number(s.mu_rmse)},
          {"mu_max_abs_error", Number(s.mu_max_abs_error)},
          {"truth_boundary_points", s.truth_boundary_points},
          {"map_boundary_points", s.map_boundary_points},
          {"boundary_error_mm", Number(s.boundary_error_mm)},
          {"boundary_error_p90_mm", Number(s.boundary_error_p90_mm)},
          {"missed_boundary_mm", Number(s.missed_boundary_mm)},
          {"misclassified_distance_mm", Number(s.misclassified_distance_mm)},
          {"regions", regions},
          {"misclassified", misclassified}};
}

}  // namespace surfmap
