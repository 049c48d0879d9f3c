#include "server/map/friction_map.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

#include <Eigen/Sparse>
#include <Eigen/SparseCholesky>
#include "absl/strings/str_cat.h"
#include "server/map/graph_distance.h"

namespace surfmap {
namespace {

constexpr double kMaxReflection = 0.999;  // keep interpolated models strictly stationary

bool HasRoughness(const TextureParams& p) { return p.sigma > 0.0 && !p.reflection.empty(); }

// Connected components of the neighbour graph (BFS), ids in order of the
// lowest vertex of each component.
std::vector<int> Components(const SurfaceLevel& level) {
  const int nv = static_cast<int>(level.limit_positions.size());
  std::vector<int> comp(nv, -1);
  std::vector<int> stack;
  int next = 0;
  for (int s = 0; s < nv; ++s) {
    if (comp[s] != -1) continue;
    comp[s] = next;
    stack.push_back(s);
    while (!stack.empty()) {
      const int v = stack.back();
      stack.pop_back();
      for (int u : level.neighbors[v]) {
        if (u >= 0 && u < nv && comp[u] == -1) {
          comp[u] = next;
          stack.push_back(u);
        }
      }
    }
    ++next;
  }
  return comp;
}

absl::Status ValidateSample(const MapSample& s, int index, int nv) {
  auto bad = [index](const std::string& what) {
    return absl::InvalidArgumentError(absl::StrCat("map sample ", index, ": ", what));
  };
  if (s.vertex < 0 || s.vertex >= nv) {
    return bad(absl::StrCat("vertex ", s.vertex, " is outside the finest level's 0..", nv - 1));
  }
  const TextureParams& p = s.params;
  if (!std::isfinite(p.mu)) return bad(absl::StrCat("mu is ", p.mu));
  if (!std::isfinite(p.mu_std) || p.mu_std < 0) return bad(absl::StrCat("mu_std is ", p.mu_std));
  if (!std::isfinite(p.sigma) || p.sigma < 0) return bad(absl::StrCat("sigma is ", p.sigma));
  for (size_t j = 0; j < p.reflection.size(); ++j) {
    if (!std::isfinite(p.reflection[j]) || std::abs(p.reflection[j]) >= 1.0) {
      return bad(absl::StrCat("reflection coefficient k", j + 1, " is ", p.reflection[j],
                              " (a stationary model needs |k| < 1)"));
    }
  }
  return absl::OkStatus();
}

}  // namespace

bool FrictionMapOptions::IsValid(std::string* why) const {
  auto fail = [why](std::string msg) {
    if (why) *why = std::move(msg);
    return false;
  };
  if (!std::isfinite(correlation_length_mm) || correlation_length_mm < 0) {
    return fail(absl::StrCat("correlation_length_mm must be >= 0 (0 = automatic), got ", correlation_length_mm));
  }
  if (!std::isfinite(prior_mu_std_floor) || prior_mu_std_floor < 0) {
    return fail(absl::StrCat("prior_mu_std_floor must be >= 0, got ", prior_mu_std_floor));
  }
  return true;
}

absl::StatusOr<FrictionMap> FrictionMap::Create(const SurfaceLevel& finest, const FrictionMapOptions& options) {
  std::string why;
  if (!options.IsValid(&why)) return absl::InvalidArgumentError(absl::StrCat("FrictionMapOptions: ", why));
  const size_t nv = finest.limit_positions.size();
  if (nv == 0) return absl::InvalidArgumentError("FrictionMap: the finest level has no vertices");
  if (finest.neighbors.size() != nv) {
    return absl::InvalidArgumentError(absl::StrCat("FrictionMap: the finest level has ", nv, " limit positions but ",
                                                   finest.neighbors.size(), " neighbour rows"));
  }
  for (size_t t = 0; t < finest.triangles.size(); ++t) {
    for (int v : finest.triangles[t]) {
      if (v < 0 || static_cast<size_t>(v) >= nv) {
        return absl::InvalidArgumentError(
            absl::StrCat("FrictionMap: finest triangle ", t, " names vertex ", v, ", outside 0..", nv - 1));
      }
    }
  }
  FrictionMap map;
  map.finest_ = &finest;
  map.options_ = options;
  map.laplacian_ = BuildGraphLaplacian(finest, options.weights);
  map.component_ = Components(finest);
  map.correlation_length_mm_ = options.correlation_length_mm;
  if (map.correlation_length_mm_ == 0.0) {
    Eigen::Vector3d lo = finest.limit_positions[0], hi = lo;
    for (const auto& p : finest.limit_positions) {
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
    map.correlation_length_mm_ = std::max(0.1 * (hi - lo).norm(), 1e-9);
  }
  return map;
}

// Harmonic extension of `fixed_values` (one row per field, one column per
// fixed vertex) into `fields` (one row per field, one value per vertex).
absl::Status FrictionMap::Solve(const std::vector<int>& fixed, const std::vector<std::vector<double>>& fixed_values,
                                std::vector<std::vector<double>>* fields) const {
  const int nv = vertex_count();
  const int nf = static_cast<int>(fixed_values.size());
  fields->assign(nf, std::vector<double>(nv, 0.0));
  // -1 fixed, -2 in a component without any fixed vertex, else the unknown's row.
  std::vector<int> row(nv, 0);
  std::vector<char> component_fixed(*std::max_element(component_.begin(), component_.end()) + 1, 0);
  for (size_t i = 0; i < fixed.size(); ++i) {
    row[fixed[i]] = -1;
    component_fixed[component_[fixed[i]]] = 1;
    for (int f = 0; f < nf; ++f) (*fields)[f][fixed[i]] = fixed_values[f][i];
  }
  int n = 0;
  for (int v = 0; v < nv; ++v) {
    if (row[v] == -1) continue;
    row[v] = component_fixed[component_[v]] ? n++ : -2;
  }
  // Unreached components: the mean of the fixed values (the prior mean).
  for (int f = 0; f < nf; ++f) {
    const double mean =
        std::accumulate(fixed_values[f].begin(), fixed_values[f].end(), 0.0) / std::max<size_t>(1, fixed.size());
    for (int v = 0; v < nv; ++v) {
      if (row[v] == -2) (*fields)[f][v] = mean;
    }
  }
  if (n == 0) return absl::OkStatus();

  std::vector<Eigen::Triplet<double>> triplets;
  triplets.reserve(laplacian_.columns.size() / 2 + n);
  Eigen::MatrixXd rhs = Eigen::MatrixXd::Zero(n, nf);
  for (int v = 0; v < nv; ++v) {
    const int r = row[v];
    if (r < 0) continue;
    double diagonal = 0.0;
    for (int e = laplacian_.offsets[v]; e < laplacian_.offsets[v + 1]; ++e) {
      const int u = laplacian_.columns[e];
      const double w = laplacian_.weights[e];
      diagonal += w;
      if (row[u] >= 0) {
        if (row[u] > r) triplets.emplace_back(row[u], r, -w);  // lower triangle only
      } else {
        for (int f = 0; f < nf; ++f) rhs(r, f) += w * (*fields)[f][u];
      }
    }
    triplets.emplace_back(r, r, diagonal);
  }
  Eigen::SparseMatrix<double> a(n, n);
  a.setFromTriplets(triplets.begin(), triplets.end());
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>, Eigen::Lower> ldlt(a);
  if (ldlt.info() != Eigen::Success) {
    return absl::InternalError(absl::StrCat("FrictionMap: factorising the ", n, "-unknown Laplace system failed"));
  }
  const Eigen::MatrixXd x = ldlt.solve(rhs);
  if (ldlt.info() != Eigen::Success || !x.allFinite()) {
    return absl::InternalError(absl::StrCat("FrictionMap: solving the ", n, "-unknown Laplace system failed"));
  }
  // Clamp to the range of the fixed values: only cotangent weights with
  // obtuse angles can overshoot it, and only slightly.
  for (int f = 0; f < nf; ++f) {
    const auto [lo, hi] = std::minmax_element(fixed_values[f].begin(), fixed_values[f].end());
    for (int v = 0; v < nv; ++v) {
      if (row[v] >= 0) (*fields)[f][v] = std::clamp(x(row[v], f), *lo, *hi);
    }
  }
  return absl::OkStatus();
}

absl::Status FrictionMap::SetSamples(std::vector<MapSample> samples) {
  const int nv = vertex_count();
  if (samples.empty()) return absl::InvalidArgumentError("FrictionMap::SetSamples: no samples");
  std::vector<int> seen(nv, -1);
  for (int i = 0; i < static_cast<int>(samples.size()); ++i) {
    if (auto status = ValidateSample(samples[i], i, nv); !status.ok()) return status;
    if (seen[samples[i].vertex] >= 0) {
      return absl::InvalidArgumentError(absl::StrCat("map sample ", i, ": vertex ", samples[i].vertex,
                                                     " already has sample ", seen[samples[i].vertex]));
    }
    seen[samples[i].vertex] = i;
  }

  // Fields: mu, then (if every sample has roughness) k1..kp and log sigma in
  // the same solve; otherwise the roughness gets its own solve over the
  // samples that have it.
  int order = 0;
  std::vector<int> all_vertices, rough_vertices;
  std::vector<int> rough_index;
  for (int i = 0; i < static_cast<int>(samples.size()); ++i) {
    all_vertices.push_back(samples[i].vertex);
    if (HasRoughness(samples[i].params)) {
      order = std::max<int>(order, samples[i].params.reflection.size());
      rough_vertices.push_back(samples[i].vertex);
      rough_index.push_back(i);
    }
  }
  auto roughness_values = [&](const std::vector<int>& indices) {
    std::vector<std::vector<double>> values(order + 1);
    for (int i : indices) {
      const TextureParams& p = samples[i].params;
      for (int j = 0; j < order; ++j) {
        const double k = j < static_cast<int>(p.reflection.size()) ? p.reflection[j] : 0.0;
        values[j].push_back(std::clamp(k, -kMaxReflection, kMaxReflection));
      }
      values[order].push_back(std::log(p.sigma));
    }
    return values;
  };
  std::vector<std::vector<double>> values(1);
  for (const auto& s : samples) values[0].push_back(s.params.mu);
  const bool joint = !rough_vertices.empty() && rough_vertices.size() == samples.size();
  if (joint) {
    auto rough = roughness_values(rough_index);
    values.insert(values.end(), rough.begin(), rough.end());
  }
  std::vector<std::vector<double>> fields;
  if (auto status = Solve(all_vertices, values, &fields); !status.ok()) return status;
  std::vector<std::vector<double>> rough_fields;
  if (joint) {
    rough_fields.assign(fields.begin() + 1, fields.end());
  } else if (!rough_vertices.empty()) {
    if (auto status = Solve(rough_vertices, roughness_values(rough_index), &rough_fields); !status.ok()) {
      return status;
    }
  }

  samples_ = std::move(samples);
  mu_ = std::move(fields[0]);
  reflection_.clear();
  log_sigma_.clear();
  if (!rough_fields.empty()) {
    reflection_.assign(rough_fields.begin(), rough_fields.begin() + order);
    log_sigma_ = std::move(rough_fields[order]);
  }
  // Prior spread s: the standard deviation of the measured mu, floored.
  double mean = 0.0;
  for (const auto& s : samples_) mean += s.params.mu;
  mean /= samples_.size();
  double var = 0.0;
  for (const auto& s : samples_) var += (s.params.mu - mean) * (s.params.mu - mean);
  var /= std::max<size_t>(1, samples_.size() - 1);
  prior_mu_std_ = std::max(std::sqrt(var), options_.prior_mu_std_floor);
  // Local value gradient g(v).
  const auto& p = finest_->limit_positions;
  mu_gradient_.assign(nv, 0.0);
  for (int v = 0; v < nv; ++v) {
    for (int u : finest_->neighbors[v]) {
      const double len = (p[u] - p[v]).norm();
      if (len > 0.0) mu_gradient_[v] = std::max(mu_gradient_[v], std::abs(mu_[u] - mu_[v]) / len);
    }
  }
  RecomputeUncertainty();
  return absl::OkStatus();
}

absl::Status FrictionMap::SetPendingVertices(std::vector<int> vertices) {
  const int nv = vertex_count();
  for (size_t i = 0; i < vertices.size(); ++i) {
    if (vertices[i] < 0 || vertices[i] >= nv) {
      return absl::InvalidArgumentError(absl::StrCat("FrictionMap::SetPendingVertices: entry ", i, " is vertex ",
                                                     vertices[i], ", outside the finest level's 0..", nv - 1));
    }
  }
  pending_ = std::move(vertices);
  if (has_samples()) RecomputeUncertainty();
  return absl::OkStatus();
}

void FrictionMap::RecomputeUncertainty() {
  const int nv = vertex_count();
  std::vector<int> sources;
  sources.reserve(samples_.size() + pending_.size());
  for (const auto& s : samples_) sources.push_back(s.vertex);
  sources.insert(sources.end(), pending_.begin(), pending_.end());  // samples first: they win ties
  const NearestSource nearest = NearestSourceDistance(*finest_, sources);
  double mean_noise_var = 0.0;
  for (const auto& s : samples_) mean_noise_var += s.params.mu_std * s.params.mu_std;
  mean_noise_var /= samples_.size();
  const double s2 = prior_mu_std_ * prior_mu_std_;
  distance_mm_ = nearest.distance_mm;
  mu_std_.assign(nv, 0.0);
  for (int v = 0; v < nv; ++v) {
    const int src = nearest.source[v];
    const double d = nearest.distance_mm[v];
    if (src < 0 || !std::isfinite(d)) {
      mu_std_[v] = std::sqrt(s2 + mean_noise_var);
      continue;
    }
    const double noise_var = src < static_cast<int>(samples_.size())
                                 ? samples_[src].params.mu_std * samples_[src].params.mu_std
                                 : mean_noise_var;
    const double spread = mu_gradient_[v] * d;
    mu_std_[v] = std::sqrt(s2 * -std::expm1(-2.0 * d / correlation_length_mm_) + spread * spread + noise_var);
  }
}

MapValue FrictionMap::VertexValue(int v) const {
  MapValue out;
  out.mu = mu_[v];
  out.mu_std = mu_std_[v];
  out.has_roughness = !log_sigma_.empty();
  if (out.has_roughness) {
    for (const auto& k : reflection_) out.reflection.push_back(k[v]);
    out.sigma = std::exp(log_sigma_[v]);
  }
  return out;
}

absl::StatusOr<MapValue> FrictionMap::ValueAt(const SurfacePoint& point) const {
  if (!has_samples()) return absl::FailedPreconditionError("FrictionMap::ValueAt: the map has no samples yet");
  const int nt = static_cast<int>(finest_->triangles.size());
  if (point.triangle < 0 || point.triangle >= nt) {
    return absl::InvalidArgumentError(
        absl::StrCat("FrictionMap::ValueAt: triangle ", point.triangle, " is outside the finest level's 0..", nt - 1));
  }
  if (!point.barycentric.allFinite()) {
    return absl::InvalidArgumentError("FrictionMap::ValueAt: barycentric coordinates are not finite");
  }
  const auto& t = finest_->triangles[point.triangle];
  const Eigen::Vector3d& b = point.barycentric;
  auto blend = [&](const std::vector<double>& f) { return b[0] * f[t[0]] + b[1] * f[t[1]] + b[2] * f[t[2]]; };
  MapValue out;
  out.mu = blend(mu_);
  out.mu_std = blend(mu_std_);
  out.has_roughness = !log_sigma_.empty();
  if (out.has_roughness) {
    for (const auto& k : reflection_) out.reflection.push_back(blend(k));
    out.sigma = std::exp(blend(log_sigma_));
  }
  return out;
}

}  // namespace surfmap
