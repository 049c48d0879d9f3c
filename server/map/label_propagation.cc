#include "server/map/label_propagation.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Sparse>
#include "absl/strings/str_cat.h"

namespace surfmap {
namespace {

// A seed weighs this many times a vertex's mean total edge weight: close to
// interpolation (the field at a seed is within ~10 % of its target where
// seeds do not conflict), while a few conflicting seeds in one triangle (a
// change point) still meet halfway instead of making the system stiff.
constexpr double kSeedStiffness = 10.0;
// Keeps a part of the surface without seeds solvable (its fields are 0).
constexpr double kRegularisation = 1e-9;

}  // namespace

absl::StatusOr<LabelPropagation> LabelPropagation::Create(const SurfaceLevel& level) {
  const int nv = static_cast<int>(level.limit_positions.size());
  if (nv == 0) return absl::InvalidArgumentError("LabelPropagation: the level has no vertices");
  for (std::size_t t = 0; t < level.triangles.size(); ++t) {
    for (int v : level.triangles[t]) {
      if (v < 0 || v >= nv) {
        return absl::InvalidArgumentError(absl::StrCat("LabelPropagation: triangle ", t, " names vertex ", v));
      }
    }
  }
  LabelPropagation p;
  p.level_ = &level;
  const GraphLaplacian g = BuildGraphLaplacian(level, LaplacianWeights::kCotangentClamped);
  double total = 0.0;
  for (int v = 0; v < nv; ++v) {
    double diagonal = 0.0;
    for (int e = g.offsets[v]; e < g.offsets[v + 1]; ++e) {
      const int u = g.columns[e];
      diagonal += g.weights[e];
      if (u > v) p.laplacian_.emplace_back(u, v, -g.weights[e]);
    }
    total += diagonal;
    p.laplacian_.emplace_back(v, v, diagonal);
  }
  const double mean = total / nv;
  for (auto& t : p.laplacian_) {
    if (t.row() == t.col()) t = Eigen::Triplet<double>(t.row(), t.col(), t.value() + kRegularisation * mean);
  }
  p.stiffness_ = kSeedStiffness * mean;
  p.ldlt_ = std::make_unique<Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>, Eigen::Lower>>();
  return p;
}

absl::StatusOr<std::vector<std::vector<double>>> LabelPropagation::Propagate(std::span<const SurfaceSeed> seeds,
                                                                             int labels) {
  const int nv = static_cast<int>(level_->limit_positions.size());
  const int nt = static_cast<int>(level_->triangles.size());
  std::vector<Eigen::Triplet<double>> triplets = laplacian_;
  Eigen::MatrixXd rhs = Eigen::MatrixXd::Zero(nv, std::max(labels, 1));
  for (const SurfaceSeed& s : seeds) {
    if (s.triangle < 0 || s.triangle >= nt || s.label < 0 || s.label >= labels) continue;
    const auto& t = level_->triangles[s.triangle];
    for (int i = 0; i < 3; ++i) {
      rhs(t[i], s.label) += stiffness_ * s.barycentric[i];
      for (int j = 0; j < 3; ++j) {
        if (t[i] >= t[j]) triplets.emplace_back(t[i], t[j], stiffness_ * s.barycentric[i] * s.barycentric[j]);
      }
    }
  }
  Eigen::SparseMatrix<double> a(nv, nv);
  a.setFromTriplets(triplets.begin(), triplets.end());
  // The pattern is the level's edges and diagonal whatever the seeds: analysed once.
  if (!analysed_) {
    ldlt_->analyzePattern(a);
    analysed_ = true;
  }
  ldlt_->factorize(a);
  if (ldlt_->info() != Eigen::Success) {
    return absl::InternalError(absl::StrCat("LabelPropagation: factorising the ", nv, "-vertex system failed"));
  }
  const Eigen::MatrixXd x = ldlt_->solve(rhs);
  if (ldlt_->info() != Eigen::Success || !x.allFinite()) {
    return absl::InternalError(absl::StrCat("LabelPropagation: solving the ", nv, "-vertex system failed"));
  }
  std::vector<std::vector<double>> fields(labels, std::vector<double>(nv));
  for (int c = 0; c < labels; ++c) {
    for (int v = 0; v < nv; ++v) fields[c][v] = std::clamp(x(v, c), 0.0, 1.0);
  }
  return fields;
}

}  // namespace surfmap
