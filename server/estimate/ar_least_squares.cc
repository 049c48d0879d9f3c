#include "server/estimate/ar_least_squares.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Cholesky>
#include <Eigen/QR>
#include "server/estimate/ar_noise.h"

namespace surfmap {

ArSolution SolveLeastSquares(const std::vector<Eigen::VectorXd>& centered, int order,
                             const std::vector<double>& noise_autocovariance) {
  ArSolution solution;
  const bool compensate = !noise_autocovariance.empty() && noise_autocovariance[0] > 0.0;
  const int p = order;
  Eigen::Index rows = 0;
  for (const auto& x : centered) rows += std::max<Eigen::Index>(0, x.size() - p);
  Eigen::MatrixXd regressors(rows, p);
  Eigen::VectorXd target(rows);
  Eigen::Index row = 0;
  for (const auto& x : centered) {
    for (Eigen::Index t = p; t < x.size(); ++t, ++row) {
      target(row) = x(t);
      for (int j = 1; j <= p; ++j) regressors(row, j - 1) = x(t - j);
    }
  }
  const Eigen::MatrixXd gram = regressors.transpose() * regressors;
  const Eigen::VectorXd moment = regressors.transpose() * target;
  const double dof = static_cast<double>(rows > p ? rows - p : rows);

  Eigen::VectorXd a;
  Eigen::MatrixXd covariance_factor;  // (X^T X [- rows C])^-1
  if (compensate) {
    // The noise adds rows c(|i - j|) to the lagged moments X^T X and rows c(i)
    // to X^T y: both removed (for white noise, rows noise_variance I and 0).
    Eigen::MatrixXd noise_moments(p, p);
    Eigen::VectorXd noise_target(p);
    for (int i = 0; i < p; ++i) {
      for (int j = 0; j < p; ++j) noise_moments(i, j) = NoiseAutocovarianceAt(noise_autocovariance, i - j);
      noise_target(i) = NoiseAutocovarianceAt(noise_autocovariance, i + 1);
    }
    const Eigen::MatrixXd compensated = gram - static_cast<double>(rows) * noise_moments;
    Eigen::LLT<Eigen::MatrixXd> llt(compensated);
    if (llt.info() != Eigen::Success) {  // de-noised moments not positive definite
      solution.noise_correction_failed = true;
      return solution;
    }
    a = llt.solve(moment - static_cast<double>(rows) * noise_target);
    covariance_factor = llt.solve(Eigen::MatrixXd::Identity(p, p));
  } else {
    // Orthogonal decomposition of X itself (not of X^T X) for accuracy near
    // the unit circle; minimum-norm solution if X is rank deficient.
    a = regressors.completeOrthogonalDecomposition().solve(target);
    covariance_factor = gram.completeOrthogonalDecomposition().pseudoInverse();
  }
  const double rss = (target - regressors * a).squaredNorm();
  double innovation_variance;
  if (compensate) {
    // The residual carries the noise through the filter (1, -a1..-ap).
    std::vector<double> taps(p + 1, 1.0);
    for (int j = 0; j < p; ++j) taps[j + 1] = -a(j);
    innovation_variance = rss / static_cast<double>(rows) -
                          FilteredNoiseProduct(noise_autocovariance, taps, taps, 0);
    if (!(innovation_variance > 0.0) || !a.allFinite()) {
      solution.noise_correction_failed = true;
      return solution;
    }
  } else {
    innovation_variance = rss / dof;
  }
  const double residual_variance = rss / dof;  // noise included
  solution.a.assign(a.data(), a.data() + p);
  solution.innovation_variance = innovation_variance;
  solution.a_stderr.resize(p);
  for (int i = 0; i < p; ++i) {
    solution.a_stderr[i] = std::sqrt(std::max(0.0, residual_variance * covariance_factor(i, i)));
  }
  return solution;
}

}  // namespace surfmap
