#include "server/estimate/series_dependence.h"

#include <algorithm>
#include <cmath>

#include "server/estimate/ar_burg.h"
#include "server/estimate/roughness.h"

namespace surfmap {
namespace {

constexpr int kOrder = 2;

}  // namespace

SeriesDependence EstimateSeriesDependence(const std::vector<Eigen::VectorXd>& segments) {
  SeriesDependence out;
  Eigen::Index n = 0;
  double sum_squares = 0.0;
  std::vector<Eigen::VectorXd> centred;
  for (const Eigen::VectorXd& x : segments) {
    if (x.size() <= kOrder) continue;  // too short to carry a lag; left out
    centred.push_back(x.array() - x.mean());
    sum_squares += centred.back().squaredNorm();
    n += x.size();
  }
  if (n < 4 * (kOrder + 1) || !(sum_squares > 0.0)) return out;
  const ArSolution solution = SolveBurg(centred, kOrder, sum_squares / static_cast<double>(n), {});
  const std::vector<double> k = ArToReflection(solution.a);
  double prediction_gain = 1.0;  // Prod(1 - k^2) = innovation variance / process variance
  for (double km : k) prediction_gain *= 1.0 - km * km;
  double sum_a = 0.0;
  for (double a : solution.a) sum_a += a;
  const double long_run = prediction_gain / ((1.0 - sum_a) * (1.0 - sum_a));
  // A model at the edge of stationarity (e.g. a series alternating in sign,
  // k1 -> -1) can make the formula 0/0: treat it as unmodelled.
  if (!std::isfinite(long_run) || !(prediction_gain > 0.0)) return out;
  out.mean_inflation = std::clamp(long_run, 1.0, static_cast<double>(n));
  out.modelled = true;
  return out;
}

}  // namespace surfmap
