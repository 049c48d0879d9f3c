#include "server/estimate/linear_detrend.h"

namespace surfmap {

void RemoveLinearTrend(double* v, int n) {
  if (n < 2) {
    if (n == 1) v[0] = 0.0;
    return;
  }
  const double mean_k = 0.5 * (n - 1);
  double mean_v = 0.0;
  for (int k = 0; k < n; ++k) mean_v += v[k];
  mean_v /= n;
  double skv = 0.0, skk = 0.0;
  for (int k = 0; k < n; ++k) {
    skv += (k - mean_k) * (v[k] - mean_v);
    skk += (k - mean_k) * (k - mean_k);
  }
  const double slope = skv / skk;
  for (int k = 0; k < n; ++k) v[k] -= mean_v + slope * (k - mean_k);
}

}  // namespace surfmap
