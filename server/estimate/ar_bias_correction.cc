#include "server/estimate/ar_bias_correction.h"

#include <bit>
#include <cmath>
#include <random>

#include "server/base/splitmix64.h"
#include "server/estimate/ar_roots.h"
#include "server/estimate/linear_detrend.h"
#include "server/estimate/roughness.h"

namespace surfmap {

std::uint64_t BiasReplicateSeed(std::uint64_t bias_seed, int replicate, int stream) {
  const std::uint64_t replicate_seed = SplitMix64(SplitMix64(bias_seed) ^ static_cast<std::uint64_t>(replicate));
  return SplitMix64(replicate_seed ^ static_cast<std::uint64_t>(stream));
}

std::uint64_t BiasSeedFromData(double mu, double start_mm) {
  return SplitMix64(SplitMix64(std::bit_cast<std::uint64_t>(mu)) ^ std::bit_cast<std::uint64_t>(start_mm));
}

ArBiasEstimate EstimateArBias(const std::vector<double>& a, double sigma, const std::vector<int>& segment_lengths,
                              const ArFitOptions& options) {
  const int p = static_cast<int>(a.size());
  ArBiasEstimate estimate;
  estimate.bias.assign(p, 0.0);
  ArFitOptions replicate_options = options;
  replicate_options.bias_replicates = 0;
  replicate_options.acf_max_lag = 1;  // the replicates' ACF is not used
  // The replicates carry white noise of the given noise's variance and are
  // fitted knowing it: the correction is for the estimator's small-sample
  // bias, which the noise's colour changes little; its lag-0 share is what
  // sets the de-noising's own spread.
  const std::vector<double> noise_autocovariance = options.NoiseAutocovariance();
  const double noise_variance = noise_autocovariance.empty() ? 0.0 : noise_autocovariance[0];
  replicate_options.noise_autocovariance.clear();
  replicate_options.noise_variance = noise_variance;
  const double noise_std = std::sqrt(noise_variance);
  const ArParams model{a, sigma};
  std::vector<double> sum(p, 0.0);
  double sigma_sum = 0.0;
  std::vector<Eigen::VectorXd> segments(segment_lengths.size());
  for (int r = 0; r < options.bias_replicates; ++r) {
    std::mt19937_64 noise_rng(BiasReplicateSeed(options.bias_seed, r, 0));
    std::normal_distribution<double> noise(0.0, 1.0);
    for (std::size_t s = 0; s < segment_lengths.size(); ++s) {
      segments[s] = SimulateRoughness(model, segment_lengths[s],
                                       BiasReplicateSeed(options.bias_seed, r, static_cast<int>(s) + 1));
      if (noise_std > 0.0) {
        for (Eigen::Index i = 0; i < segments[s].size(); ++i) segments[s](i) += noise_std * noise(noise_rng);
      }
      if (options.segments_detrended) RemoveLinearTrend(segments[s].data(), static_cast<int>(segments[s].size()));
    }
    const absl::StatusOr<ArFit> fit = FitAutoregressive(segments, replicate_options);
    if (!fit.ok()) continue;
    for (int j = 0; j < p; ++j) sum[j] += fit->a[j];
    sigma_sum += fit->sigma;
    ++estimate.replicates_used;
  }
  if (estimate.replicates_used == 0) return estimate;
  for (int j = 0; j < p; ++j) estimate.bias[j] = sum[j] / estimate.replicates_used - a[j];
  estimate.sigma_bias = sigma_sum / estimate.replicates_used - sigma;
  return estimate;
}

std::vector<double> ApplyArBiasCorrection(const std::vector<double>& a, const std::vector<double>& bias) {
  for (double t = 1.0; t >= 0.1; t *= 0.5) {
    std::vector<double> corrected(a.size());
    for (std::size_t j = 0; j < a.size(); ++j) corrected[j] = a[j] - t * bias[j];
    if (ArLargestRootModulus(corrected) < 1.0) return corrected;
  }
  return a;
}

}  // namespace surfmap
