#include "clients/mapsim/map_evaluation.h"

#include <cmath>
#include <limits>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"
#include "server/map/material_classification.h"

namespace surfmap::mapsim {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// Vertices with a neighbour of another label.
std::vector<int> BoundaryVertices(const SurfaceLevel& level, const std::vector<int>& label) {
  std::vector<int> out;
  for (size_t v = 0; v < label.size(); ++v) {
    for (int n : level.neighbors[v]) {
      if (label[n] != label[v]) {
        out.push_back(static_cast<int>(v));
        break;
      }
    }
  }
  return out;
}

// Mean over `from` of the distance to the nearest vertex of `to`. Brute
// force: boundary sets are a few thousand vertices at most.
double MeanNearestDistance(const SurfaceLevel& level, const std::vector<int>& from, const std::vector<int>& to) {
  if (from.empty() || to.empty()) return kNaN;
  double sum = 0.0;
  for (int a : from) {
    double best = std::numeric_limits<double>::infinity();
    for (int b : to) best = std::min(best, (level.limit_positions[a] - level.limit_positions[b]).squaredNorm());
    sum += std::sqrt(best);
  }
  return sum / static_cast<double>(from.size());
}

}  // namespace

absl::StatusOr<MapEvaluation> EvaluateMap(const SurfaceLevel& level, const std::vector<double>& map_mu,
                                          const std::vector<int>& truth_material,
                                          const std::vector<double>& material_mus,
                                          const std::vector<std::string>& material_names) {
  const size_t n = level.limit_positions.size();
  if (map_mu.size() != n || truth_material.size() != n || level.neighbors.size() != n) {
    return absl::InvalidArgumentError(absl::StrCat("EvaluateMap: the level has ", n, " vertices but the map has ",
                                                   map_mu.size(), " values and the truth ", truth_material.size()));
  }
  if (material_mus.empty() || material_names.size() != material_mus.size()) {
    return absl::InvalidArgumentError(absl::StrCat("EvaluateMap: ", material_mus.size(), " material mus and ",
                                                   material_names.size(), " names (need as many, at least one)"));
  }
  const int materials = static_cast<int>(material_mus.size());
  for (size_t v = 0; v < n; ++v) {
    if (truth_material[v] < 0 || truth_material[v] >= materials) {
      return absl::InvalidArgumentError(
          absl::StrCat("EvaluateMap: truth material ", truth_material[v], " of vertex ", v, " out of range"));
    }
  }
  absl::StatusOr<std::vector<int>> classes = ClassifyNearestMaterial(map_mu, material_mus);
  if (!classes.ok()) return absl::InvalidArgumentError(absl::StrCat("EvaluateMap: ", classes.status().message()));

  MapEvaluation e;
  e.vertices = static_cast<int>(n);
  std::vector<double> sum(materials, 0.0), sum_sq(materials, 0.0);
  std::vector<int> count(materials, 0);
  double total_sq = 0.0;
  int right = 0;
  for (size_t v = 0; v < n; ++v) {
    const int m = truth_material[v];
    const double err = map_mu[v] - material_mus[m];
    total_sq += err * err;
    e.mu_max_abs_error = std::max(e.mu_max_abs_error, std::abs(err));
    right += (*classes)[v] == m;
    sum[m] += map_mu[v];
    sum_sq[m] += err * err;
    ++count[m];
  }
  e.mu_rmse = n ? std::sqrt(total_sq / static_cast<double>(n)) : kNaN;
  e.classification_accuracy = n ? static_cast<double>(right) / static_cast<double>(n) : kNaN;
  for (int m = 0; m < materials; ++m) {
    MaterialEvaluation me;
    me.name = material_names[m];
    me.truth_mu = material_mus[m];
    me.vertices = count[m];
    me.map_mu_mean = count[m] ? sum[m] / count[m] : kNaN;
    me.map_mu_rmse = count[m] ? std::sqrt(sum_sq[m] / count[m]) : kNaN;
    e.materials.push_back(me);
  }
  const std::vector<int> truth_boundary = BoundaryVertices(level, truth_material);
  const std::vector<int> map_boundary = BoundaryVertices(level, *classes);
  e.truth_boundary_vertices = static_cast<int>(truth_boundary.size());
  e.map_boundary_vertices = static_cast<int>(map_boundary.size());
  e.boundary_error_mm = MeanNearestDistance(level, truth_boundary, map_boundary);
  e.spurious_boundary_mm = MeanNearestDistance(level, map_boundary, truth_boundary);
  return e;
}

}  // namespace surfmap::mapsim
