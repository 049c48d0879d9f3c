#include "server/estimate/series_noise.h"

#include <algorithm>
#include <random>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"
#include "server/base/splitmix64.h"
#include "server/estimate/force_variation.h"

namespace surfmap {
namespace {

constexpr int kMaxReplicates = 64;
constexpr int kMaxLag = 20;

void AddNoise(std::span<const DragSample> clean, double noise_std, std::mt19937_64& rng,
              std::vector<DragSample>& out) {
  std::normal_distribution<double> gauss(0.0, noise_std);
  out.assign(clean.begin(), clean.end());
  for (DragSample& sample : out) {
    for (int axis = 0; axis < 3; ++axis) sample.force[axis] += gauss(rng);
  }
}

}  // namespace

absl::StatusOr<std::vector<std::vector<double>>> PropagateSeriesNoise(
    std::span<const DragSample> forward, std::span<const DragSample> reverse, const PathPairing& pairing,
    const DataWindow& window, const FrictionOptions& friction_options, const FrictionFit& friction,
    std::span<const SeriesStretch> stretches, const SeriesNoiseOptions& options) {
  if (options.replicates < 1 || options.replicates > kMaxReplicates) {
    return absl::InvalidArgumentError(
        absl::StrCat("noise replicates ", options.replicates, " is outside 1..", kMaxReplicates));
  }
  if (options.max_lag < 0 || options.max_lag > kMaxLag) {
    return absl::InvalidArgumentError(absl::StrCat("noise max_lag ", options.max_lag, " is outside 0..", kMaxLag));
  }
  const int lags = options.max_lag + 1;
  std::vector<std::vector<double>> result(stretches.size(), std::vector<double>(lags, 0.0));
  if (!(options.noise_std > 0.0)) return result;

  std::vector<std::vector<Eigen::VectorXd>> clean;
  clean.reserve(stretches.size());
  for (const SeriesStretch& stretch : stretches) {
    absl::StatusOr<std::vector<Eigen::VectorXd>> series = ForceVariationSeries(
        forward, reverse, pairing, friction, stretch.start_mm, stretch.end_mm, stretch.mu, options.step_mm,
        options.series);
    if (!series.ok()) return series.status();
    clean.push_back(*std::move(series));
  }

  std::vector<std::vector<double>> products(stretches.size(), std::vector<double>(lags, 0.0));
  std::vector<std::vector<double>> counts(stretches.size(), std::vector<double>(lags, 0.0));
  std::vector<DragSample> noisy_forward, noisy_reverse;
  for (int r = 0; r < options.replicates; ++r) {
    std::mt19937_64 rng(SplitMix64(SplitMix64(options.seed) ^ static_cast<std::uint64_t>(r)));
    AddNoise(forward, options.noise_std, rng, noisy_forward);
    AddNoise(reverse, options.noise_std, rng, noisy_reverse);
    absl::StatusOr<FrictionFit> noisy_friction =
        FitFriction(noisy_forward, noisy_reverse, pairing, window, friction_options);
    if (!noisy_friction.ok()) {
      return absl::InvalidArgumentError(absl::StrCat("noise replicate ", r, ": ", noisy_friction.status().message()));
    }
    for (std::size_t k = 0; k < stretches.size(); ++k) {
      const SeriesStretch& stretch = stretches[k];
      absl::StatusOr<std::vector<Eigen::VectorXd>> noisy =
          ForceVariationSeries(noisy_forward, noisy_reverse, pairing, *noisy_friction, stretch.start_mm,
                               stretch.end_mm, stretch.mu, options.step_mm, options.series);
      if (!noisy.ok()) return noisy.status();
      for (std::size_t segment = 0; segment < noisy->size(); ++segment) {
        const Eigen::VectorXd d = (*noisy)[segment] - clean[k][segment];
        const Eigen::Index n = d.size();
        for (int lag = 0; lag < lags && lag < n; ++lag) {
          products[k][lag] += d.head(n - lag).dot(d.tail(n - lag));
          counts[k][lag] += static_cast<double>(n - lag);
        }
      }
    }
  }
  for (std::size_t k = 0; k < stretches.size(); ++k) {
    for (int lag = 0; lag < lags; ++lag) {
      if (counts[k][lag] > 0.0) result[k][lag] = products[k][lag] / counts[k][lag];
    }
    // Averaged over fewer products, a far lag can come out larger than lag 0
    // by sampling error; no autocovariance can.
    for (int lag = 1; lag < lags; ++lag) result[k][lag] = std::clamp(result[k][lag], -result[k][0], result[k][0]);
  }
  return result;
}

}  // namespace surfmap
