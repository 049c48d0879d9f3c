#include "clients/rig/map_score.h"

#include <cmath>
#include <limits>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "clients/rig/json_number.h"

namespace surfmap::rig {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

int NearestMaterial(const Scene& scene, double mu) {
  int best = 0;
  for (int m = 1; m < static_cast<int>(scene.materials.size()); ++m) {
    if (std::abs(scene.materials[m].mu - mu) < std::abs(scene.materials[best].mu - mu)) best = m;
  }
  return best;
}

// Index into scene.regions of the first region holding `p`, or -1 (default material).
int RegionIndexAt(const Scene& scene, const Eigen::Vector3d& p) {
  for (size_t r = 0; r < scene.regions.size(); ++r) {
    if (scene.regions[r].Contains(p)) return static_cast<int>(r);
  }
  return -1;
}

}  // namespace

absl::StatusOr<MapScore> ScoreMap(const Scene& scene, const cli::MapDocument& map) {
  if (map.positions.size() != map.mu.size() || map.positions.empty()) {
    return absl::FailedPreconditionError(
        "the map has no vertex positions: write it with `surfmap map get JOB --format json` (which includes the mesh)");
  }
  if (scene.materials.empty()) return absl::FailedPreconditionError(scene.name + ": scene has no materials");
  MapScore score;
  score.vertices = static_cast<int>(map.mu.size());
  score.samples = static_cast<int>(map.samples.size());
  const int region_count = static_cast<int>(scene.regions.size());
  score.regions.resize(region_count + 1);
  for (int r = 0; r <= region_count; ++r) {
    RegionScore& rs = score.regions[r];
    const int material = r < region_count ? scene.regions[r].material : scene.default_material;
    rs.material = scene.material_names[material];
    rs.truth_mu = scene.materials[material].mu;
    rs.name = r < region_count ? absl::StrCat(rs.material, " (regions[", r, "])") : rs.material + " (default)";
  }
  std::vector<double> sum(region_count + 1, 0.0), sum2(region_count + 1, 0.0);
  double squared = 0.0;
  int right = 0;
  for (size_t i = 0; i < map.mu.size(); ++i) {
    const Eigen::Vector3d p(map.positions[i][0], map.positions[i][1], map.positions[i][2]);
    const int region = RegionIndexAt(scene, p);
    const int slot = region < 0 ? region_count : region;
    const int material = region < 0 ? scene.default_material : scene.regions[region].material;
    RegionScore& rs = score.regions[slot];
    ++rs.vertices;
    const double mu = map.mu[i];
    if (!std::isfinite(mu) || !p.allFinite()) continue;
    ++rs.vertices_with_mu;
    ++score.vertices_with_mu;
    sum[slot] += mu;
    sum2[slot] += mu * mu;
    const double error = mu - scene.materials[material].mu;
    squared += error * error;
    score.mu_max_abs_error = std::max(score.mu_max_abs_error, std::abs(error));
    if (NearestMaterial(scene, mu) == material) ++right;
  }
  if (score.vertices_with_mu == 0) return absl::FailedPreconditionError("the map has no vertex with a mu value");
  score.mu_rmse = std::sqrt(squared / score.vertices_with_mu);
  score.classification_accuracy = static_cast<double>(right) / score.vertices_with_mu;
  for (int r = 0; r <= region_count; ++r) {
    RegionScore& rs = score.regions[r];
    if (rs.vertices_with_mu == 0) {
      rs.map_mu_mean = rs.map_mu_std = kNaN;
      continue;
    }
    const double n = rs.vertices_with_mu;
    rs.map_mu_mean = sum[r] / n;
    rs.map_mu_std = std::sqrt(std::max(0.0, sum2[r] / n - rs.map_mu_mean * rs.map_mu_mean));
  }
  return score;
}

std::string FormatMapScore(const MapScore& s, const std::string& scene_name) {
  std::string out = absl::StrFormat("map vs scene '%s': %d vertices (%d with mu), %d samples\n", scene_name,
                                    s.vertices, s.vertices_with_mu, s.samples);
  absl::StrAppendFormat(&out, "  mu RMSE over vertices      %.4f  (max |error| %.3f)\n", s.mu_rmse,
                        s.mu_max_abs_error);
  absl::StrAppendFormat(&out, "  vertices classified right  %.1f %%\n", 100.0 * s.classification_accuracy);
  absl::StrAppendFormat(&out, "  %-26s %8s %8s %8s %8s %8s\n", "region", "vertices", "truth", "map", "map std",
                        "error");
  for (const RegionScore& r : s.regions) {
    if (r.vertices == 0) continue;
    if (r.vertices_with_mu == 0) {
      absl::StrAppendFormat(&out, "  %-26s %8d %8.3f %8s %8s %8s\n", r.name, r.vertices, r.truth_mu, "-", "-", "-");
      continue;
    }
    absl::StrAppendFormat(&out, "  %-26s %8d %8.3f %8.3f %8.3f %+8.3f\n", r.name, r.vertices, r.truth_mu,
                          r.map_mu_mean, r.map_mu_std, r.map_mu_mean - r.truth_mu);
  }
  return out;
}

nlohmann::json MapScoreToJson(const MapScore& s, const std::string& scene_name) {
  nlohmann::json regions = nlohmann::json::array();
  for (const RegionScore& r : s.regions) {
    regions.push_back({{"name", r.name},
                       {"material", r.material},
                       {"truth_mu", FiniteOrNull(r.truth_mu)},
                       {"vertices", r.vertices},
                       {"vertices_with_mu", r.vertices_with_mu},
                       {"map_mu_mean", FiniteOrNull(r.map_mu_mean)},
                       {"map_mu_std", FiniteOrNull(r.map_mu_std)}});
  }
  return {{"scene", scene_name},
          {"vertices", s.vertices},
          {"vertices_with_mu", s.vertices_with_mu},
          {"samples", s.samples},
          {"mu_rmse", FiniteOrNull(s.mu_rmse)},
          {"mu_max_abs_error", FiniteOrNull(s.mu_max_abs_error)},
          {"classification_accuracy", FiniteOrNull(s.classification_accuracy)},
          {"regions", regions}};
}

}  // namespace surfmap::rig
