// Autocorrelation pieces of the AR fit: the pooled sample autocovariance of
// several segments, the theoretical ACF of a fitted model, and the correlation
// length read off an ACF.
#pragma once

#include <optional>
#include <vector>

#include <Eigen/Core>

namespace surfmap {

// Biased sample autocovariance c(0..max_lag) pooled over already mean-removed
// segments: c(k) = sum over segments of sum_t x(t) x(t+k), divided by the total
// number of samples. Pairs never span a segment boundary. max_lag < 0 gives an
// empty vector.
Eigen::VectorXd PooledAutocovariance(const std::vector<Eigen::VectorXd>& centered, int max_lag);

// Theoretical autocorrelation rho(0..max_lag) of the AR model a1..ap (rho(0) = 1):
// rho(1..p) by the inverse Levinson recursion from the reflection coefficients,
// then rho(k) = sum_j a_j rho(k-j). Empty when the model is not stationary
// (some |k| >= 1) or max_lag < 0.
std::vector<double> ArModelAutocorrelation(const std::vector<double>& a, int max_lag);

// Correlation length in lags: the lag after which |acf| stays below 1/e,
// interpolated log-linearly between the last lag K with |acf(K)| >= 1/e and
// K + 1 (linearly if acf(K + 1) == 0), so acf = a^k gives exactly -1/ln(a).
// None when the last given lag is still >= 1/e (the ACF does not settle within
// the lags given) or acf is empty.
std::optional<double> CorrelationLengthLags(const std::vector<double>& acf);

}  // namespace surfmap
