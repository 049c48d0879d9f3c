#include "server/estimate/ar_autocorrelation.h"

#include <algorithm>
#include <cmath>

#include "server/estimate/lag_products.h"
#include "server/estimate/roughness.h"

namespace surfmap {

Eigen::VectorXd PooledAutocovariance(const std::vector<Eigen::VectorXd>& centered, int max_lag) {
  if (max_lag < 0) return Eigen::VectorXd();
  Eigen::VectorXd c = Eigen::VectorXd::Zero(max_lag + 1);
  Eigen::Index total = 0;
  for (const auto& x : centered) {
    const int n = static_cast<int>(x.size());
    total += n;
    AddLagProducts(x.data(), n, std::min(max_lag + 1, n), c.data());
  }
  if (total > 0) c /= static_cast<double>(total);
  return c;
}

std::vector<double> ArModelAutocorrelation(const std::vector<double>& a, int max_lag) {
  if (max_lag < 0) return {};
  const int p = static_cast<int>(a.size());
  const std::vector<double> k = ArToReflection(a);
  for (double km : k) {
    if (!(std::abs(km) < 1.0)) return {};
  }
  // Inverse Levinson with rho(0) = 1: given the order m-1 model phi and its
  // prediction error power e, k_m = (rho(m) - sum_j phi_j rho(m-j)) / e.
  std::vector<double> rho(std::max(max_lag, p) + 1, 0.0);
  rho[0] = 1.0;
  std::vector<double> phi;
  double e = 1.0;
  for (int m = 1; m <= p; ++m) {
    double s = 0.0;
    for (int j = 1; j < m; ++j) s += phi[j - 1] * rho[m - j];
    rho[m] = k[m - 1] * e + s;
    std::vector<double> next(m);
    for (int j = 1; j < m; ++j) next[j - 1] = phi[j - 1] - k[m - 1] * phi[m - j - 1];
    next[m - 1] = k[m - 1];
    phi = std::move(next);
    e *= 1.0 - k[m - 1] * k[m - 1];
  }
  for (int lag = p + 1; lag <= max_lag; ++lag) {
    double s = 0.0;
    for (int j = 1; j <= p; ++j) s += a[j - 1] * rho[lag - j];
    rho[lag] = s;
  }
  rho.resize(max_lag + 1);
  return rho;
}

std::optional<double> CorrelationLengthLags(const std::vector<double>& acf) {
  const double threshold = std::exp(-1.0);
  const int n = static_cast<int>(acf.size());
  if (n == 0 || std::abs(acf.back()) >= threshold) return std::nullopt;
  int last_above = -1;  // last lag with |acf| >= 1/e
  for (int lag = n - 1; lag >= 0; --lag) {
    if (std::abs(acf[lag]) >= threshold) {
      last_above = lag;
      break;
    }
  }
  if (last_above < 0) return 0.0;  // below 1/e from lag 0 on (degenerate input)
  const double hi = std::abs(acf[last_above]);
  const double lo = std::abs(acf[last_above + 1]);
  double fraction;
  if (lo > 0.0) {
    fraction = (std::log(hi) + 1.0) / (std::log(hi) - std::log(lo));
  } else {
    fraction = (hi - threshold) / hi;
  }
  return last_above + std::clamp(fraction, 0.0, 1.0);
}

}  // namespace surfmap
