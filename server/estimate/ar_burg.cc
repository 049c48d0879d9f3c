#include "server/estimate/ar_burg.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Cholesky>
#include "server/estimate/ar_autocorrelation.h"
#include "server/estimate/ar_noise.h"
#include "server/estimate/roughness.h"

namespace surfmap {
namespace {

// sqrt(diag(sigma^2 Gamma_p^-1) / n). sigma^2 / gamma(0) = prod(1 - k^2), so
// this only needs the model's autocorrelation. Zero for a model on the unit
// circle (perfectly predictable series), where the asymptotic variance is 0.
std::vector<double> AsymptoticStdErr(const std::vector<double>& a, const std::vector<double>& k,
                                     Eigen::Index n) {
  const int p = static_cast<int>(a.size());
  std::vector<double> stderr_a(p, 0.0);
  const std::vector<double> rho = ArModelAutocorrelation(a, p - 1);
  if (rho.empty() || n <= 0) return stderr_a;
  double prediction_gain = 1.0;
  for (double km : k) prediction_gain *= 1.0 - km * km;
  Eigen::MatrixXd toeplitz(p, p);
  for (int i = 0; i < p; ++i) {
    for (int j = 0; j < p; ++j) toeplitz(i, j) = rho[std::abs(i - j)];
  }
  const Eigen::MatrixXd inverse = toeplitz.ldlt().solve(Eigen::MatrixXd::Identity(p, p));
  for (int i = 0; i < p; ++i) {
    stderr_a[i] = std::sqrt(std::max(0.0, prediction_gain * inverse(i, i) / static_cast<double>(n)));
  }
  return stderr_a;
}

}  // namespace

ArSolution SolveBurg(const std::vector<Eigen::VectorXd>& centered, int order, double variance,
                     const std::vector<double>& noise_autocovariance) {
  const bool compensate = !noise_autocovariance.empty() && noise_autocovariance[0] > 0.0;
  ArSolution solution;
  // Forward (f) and backward (b) prediction errors per segment. After stage m,
  // f[t] and b[t] are valid for t >= m; stage m pairs f[t] with b[t-1].
  std::vector<Eigen::VectorXd> f = centered;
  std::vector<Eigen::VectorXd> b = centered;
  Eigen::Index n_total = 0;
  for (const auto& x : centered) n_total += x.size();

  std::vector<double> phi;  // order m-1 model
  std::vector<double> k;
  double error_power = variance - NoiseAutocovarianceAt(noise_autocovariance, 0);
  if (error_power <= 0.0) {
    solution.noise_correction_failed = true;
    return solution;
  }
  for (int m = 1; m <= order; ++m) {
    double numerator = 0.0;
    double denominator = 0.0;
    double pairs = 0.0;
    for (std::size_t s = 0; s < f.size(); ++s) {
      const Eigen::Index n = f[s].size();
      const auto fs = f[s].segment(m, n - m);
      const auto bs = b[s].segment(m - 1, n - m);
      numerator += fs.dot(bs);
      denominator += fs.squaredNorm() + bs.squaredNorm();
      pairs += static_cast<double>(n - m);
    }
    if (compensate) {
      // Expected noise contributions to sum f[t] b[t-1] and to
      // sum f[t]^2 + b[t-1]^2: both errors are the noise filtered by the
      // order m-1 prediction filter, f[t] with taps (1, -phi_1..-phi_{m-1})
      // at delays 0..m-1, b[t-1] with the same taps at delays m..1. For white
      // noise this is N_m noise_variance sum phi_j phi_(m-j) and
      // 2 N_m noise_variance (1 + sum phi_j^2).
      std::vector<double> taps(m, 1.0);
      for (int j = 1; j < m; ++j) taps[j] = -phi[j - 1];
      std::vector<double> reversed(taps.rbegin(), taps.rend());  // b[t-1] taps at delays 1..m
      numerator -= pairs * FilteredNoiseProduct(noise_autocovariance, taps, reversed, 1);
      denominator -= 2.0 * pairs * FilteredNoiseProduct(noise_autocovariance, taps, taps, 0);
    }
    if (!(denominator > 0.0)) {
      if (compensate) {
        solution.noise_correction_failed = true;
        return solution;
      }
      // Plain Burg: all errors zero, the series is predicted perfectly.
      denominator = 1.0;
      numerator = 0.0;
    }
    double km = 2.0 * numerator / denominator;
    if (!(std::abs(km) < 1.0)) {
      // Plain Burg has |k| <= 1 by Cauchy-Schwarz (equality only for a
      // perfectly predictable series); the compensated one can overshoot.
      if (compensate) {
        solution.noise_correction_failed = true;
        return solution;
      }
      km = std::clamp(km, -1.0, 1.0);
    }
    for (std::size_t s = 0; s < f.size(); ++s) {
      for (Eigen::Index t = f[s].size() - 1; t >= m; --t) {  // descending: b[t-1] still old
        const double ft = f[s](t);
        const double bt1 = b[s](t - 1);
        f[s](t) = ft - km * bt1;
        b[s](t) = bt1 - km * ft;
      }
    }
    std::vector<double> next(m);
    for (int j = 1; j < m; ++j) next[j - 1] = phi[j - 1] - km * phi[m - j - 1];
    next[m - 1] = km;
    phi = std::move(next);
    k.push_back(km);
    error_power *= 1.0 - km * km;
  }
  solution.a = phi;
  solution.innovation_variance = error_power;
  solution.a_stderr = AsymptoticStdErr(solution.a, k, n_total);
  return solution;
}

}  // namespace surfmap
