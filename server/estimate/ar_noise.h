// Measurement noise riding on an AR series, as the noise-compensated AR
// estimators see it: its autocovariance at lags 0, 1, ... (N^2). White noise
// is one entry; lags past the end are 0.
#pragma once

#include <vector>

namespace surfmap {

// c(|lag|), 0 past the given lags.
inline double NoiseAutocovarianceAt(const std::vector<double>& c, int lag) {
  if (lag < 0) lag = -lag;
  return lag < static_cast<int>(c.size()) ? c[lag] : 0.0;
}

// Expected product of two FIR filters of the noise:
// E[(sum_i u_i n(t - i)) (sum_j v_j n(t - shift - j))]
// = sum_i sum_j u_i v_j c(i - shift - j).
double FilteredNoiseProduct(const std::vector<double>& c, const std::vector<double>& u,
                            const std::vector<double>& v, int shift);

}  // namespace surfmap
