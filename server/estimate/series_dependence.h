// How serial correlation inflates the sampling error of a series' mean. The
// per-pair friction of a drag rides on the surface texture, which is
// correlated over a few tenths of a mm: rubber's AR(2) root 0.88 on the
// 0.1 mm grid makes a mean over 160 pairs worth only ~11 independent ones, so
// a standard error that took the pairs as independent would claim ~4x too
// much precision.
#pragma once

#include <vector>

#include <Eigen/Core>

namespace surfmap {

struct SeriesDependence {
  // var(sample mean) = mean_inflation * variance / n: the long-run variance
  // over the variance, Prod(1 - k_i^2) / (1 - sum a_i)^2 for an AR model with
  // reflection coefficients k and coefficients a.
  double mean_inflation = 1.0;
  // False when the series was too short or degenerate to model: the
  // inflation is then 1 (independent data).
  bool modelled = false;
};

// Fits AR(2) by Burg to the mean-removed `segments` (no lag spans two
// segments) and derives the inflation from the model, clamped to [1, n]
// (never claim more than independent data, never less than one effective
// sample). Fewer than 12 samples in all, no variance or a model at the edge
// of stationarity give the unmodelled default. It is an estimate: on a short
// series Burg's coefficients are biased towards a less persistent model, so
// for strongly correlated textures it errs low.
SeriesDependence EstimateSeriesDependence(const std::vector<Eigen::VectorXd>& segments);

}  // namespace surfmap
