// The small-sample bias correction against synthetic AR(2) data with a known
// answer: the paper's textures, two segments of 50 points each (a 5 mm piece
// of a drag at the 0.1 mm grid, both passes: the shortest piece FitTrace fits),
// each detrended as ForceVariationSeries does.
#include "server/estimate/ar_bias_correction.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <set>
#include <vector>

#include <gtest/gtest.h>
#include "server/base/splitmix64.h"
#include "server/base/testing/status_matchers.h"
#include "server/estimate/ar_roots.h"
#include "server/estimate/linear_detrend.h"
#include "server/estimate/roughness.h"

namespace surfmap {
namespace {

using status_matchers::StatusIs;

constexpr int kSegment = 50;
constexpr int kSeeds = 200;
// Tolerance on the mean over kSeeds of a corrected coefficient: three
// standard errors of that mean (spread ~0.1 at n = 2 x 50, / sqrt(200) =
// 0.007, x 3 = 0.021) plus the second-order bias a one-step correction leaves
// (it evaluates the bias at the biased estimate: ~0.01 at this length,
// measured at 0.003-0.011 on rubber for n = 60..100 per segment).
constexpr double kMeanTolerance = 0.03;
// The same for sigma, relative: its spread at n = 2 x 50 is ~sigma / sqrt(2n)
// = 7 %, / sqrt(200) x 3 = 1.5 %, plus the one-step correction's remainder
// (~1 %, measured: the raw bias is 4 %).
constexpr double kSigmaMeanTolerance = 0.025;

struct Means {
  double raw_a1 = 0.0, raw_a2 = 0.0, corrected_a1 = 0.0, corrected_a2 = 0.0, raw_sigma = 0.0, corrected_sigma = 0.0;
  int corrected_stationary = 0;
  // Medians, not means, of the models' process variance sigma^2 / prod(1 - k^2):
  // it is heavy-tailed near the unit circle.
  double raw_variance_median = 0.0, corrected_variance_median = 0.0;
};

double Median(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  return values.empty() ? 0.0 : values[values.size() / 2];
}

// Each segment has a least-squares line removed, and the options say so, as
// FitPieceRoughness does.
Means MeanFits(const ArParams& truth, double noise_std) {
  Means m;
  std::vector<double> raw_variances, corrected_variances;
  std::mt19937_64 rng(99);
  std::normal_distribution<double> noise(0.0, 1.0);
  for (int seed = 1; seed <= kSeeds; ++seed) {
    std::vector<Eigen::VectorXd> segments;
    for (int s = 0; s < 2; ++s) {
      Eigen::VectorXd x = SimulateRoughness(truth, kSegment, 100 * seed + s);
      for (Eigen::Index i = 0; i < x.size(); ++i) x(i) += noise_std * noise(rng);
      RemoveLinearTrend(x.data(), kSegment);
      segments.push_back(std::move(x));
    }
    ArFitOptions options;
    options.noise_variance = noise_std * noise_std;
    options.segments_detrended = true;
    const absl::StatusOr<ArFit> raw = FitAutoregressive(segments, options);
    options.bias_replicates = 64;
    options.bias_seed = seed;
    const absl::StatusOr<ArFit> corrected = FitAutoregressive(segments, options);
    EXPECT_TRUE(raw.ok() && corrected.ok()) << "seed " << seed;
    if (!raw.ok() || !corrected.ok()) continue;
    m.raw_a1 += raw->a[0] / kSeeds;
    m.raw_a2 += raw->a[1] / kSeeds;
    m.corrected_a1 += corrected->a[0] / kSeeds;
    m.corrected_a2 += corrected->a[1] / kSeeds;
    m.raw_sigma += raw->sigma / kSeeds;
    m.corrected_sigma += corrected->sigma / kSeeds;
    m.corrected_stationary += corrected->stationary ? 1 : 0;
    raw_variances.push_back(ArProcessVariance(raw->a, raw->sigma));
    corrected_variances.push_back(ArProcessVariance(corrected->a, corrected->sigma));
  }
  m.raw_variance_median = Median(std::move(raw_variances));
  m.corrected_variance_median = Median(std::move(corrected_variances));
  std::printf("AR(2) truth %.2f / %.2f, noise %.2f, 2 x %d points, mean of %d: raw %.3f / %.3f, corrected %.3f / %.3f\n",
              truth.a[0], truth.a[1], noise_std, kSegment, kSeeds, m.raw_a1, m.raw_a2, m.corrected_a1,
              m.corrected_a2);
  std::printf("  sigma truth %.3f: raw %.4f, corrected %.4f\n", truth.sigma, m.raw_sigma, m.corrected_sigma);
  return m;
}

TEST(ArBiasCorrectionTest, RubberShortPieceIsUnbiased) {
  const Means m = MeanFits(ArParams{{0.60, 0.25}, 0.11}, 0.0);
  // The problem exists at this length (else the test could not fail)...
  EXPECT_LT(m.raw_a2, 0.25 - 0.06);
  // ...and the correction removes it.
  EXPECT_NEAR(m.corrected_a1, 0.60, kMeanTolerance);
  EXPECT_NEAR(m.corrected_a2, 0.25, kMeanTolerance);
  EXPECT_EQ(m.corrected_stationary, kSeeds);
  // sigma too: low before (the problem exists), right after.
  EXPECT_LT(m.raw_sigma, 0.11 * (1.0 - kSigmaMeanTolerance));
  EXPECT_NEAR(m.corrected_sigma, 0.11, 0.11 * kSigmaMeanTolerance);
}

// With the options at their defaults (a caller that never detrends), the
// estimated bias is that of the plain (mean-removed) fit: the known answer is
// the mean error of that fit over kBiasSeries independent 2 x kSegment series.
// Replicates that were detrended (the old default) estimate the bias of a
// different estimator, 0.04 (rubber) to 0.06 (AR(1) 0.9) more negative,
// measured.
// Tolerance: both sides are means of kBiasSeries fits with spread <= 0.1
// (sqrt((1 - a_p^2) / n) at n = 100, a little more at this length), so their
// difference has a standard error <= 0.1 * sqrt(2 / 4000) = 0.0022; 0.01 is
// 4.5 of those, and a quarter of the smallest error the old default made.
TEST(ArBiasCorrectionTest, DefaultOptionsEstimateTheBiasOfTheUndetrendedFit) {
  constexpr int kBiasSeries = 4000;
  constexpr double kBiasTolerance = 0.01;
  for (const ArParams& truth : {ArParams{{0.60, 0.25}, 0.11}, ArParams{{0.9}, 0.1}}) {
    const int p = static_cast<int>(truth.a.size());
    ArFitOptions options;
    options.order = p;
    std::vector<double> mean_error(p, 0.0);
    int fits = 0;
    for (int seed = 0; seed < kBiasSeries; ++seed) {
      const std::vector<Eigen::VectorXd> segments{SimulateRoughness(truth, kSegment, 2 * seed + 1000000),
                                                  SimulateRoughness(truth, kSegment, 2 * seed + 1000001)};
      const absl::StatusOr<ArFit> fit = FitAutoregressive(segments, options);
      if (!fit.ok()) continue;
      for (int j = 0; j < p; ++j) mean_error[j] += fit->a[j] - truth.a[j];
      ++fits;
    }
    ASSERT_GT(fits, kBiasSeries * 9 / 10);
    options.bias_replicates = kBiasSeries;
    const ArBiasEstimate estimate = EstimateArBias(truth.a, truth.sigma, {kSegment, kSegment}, options);
    ASSERT_GT(estimate.replicates_used, kBiasSeries * 9 / 10);
    for (int j = 0; j < p; ++j) {
      EXPECT_NEAR(estimate.bias[j], mean_error[j] / fits, kBiasTolerance) << "a" << j + 1 << " of AR(" << p << ")";
    }
  }
}

TEST(ArBiasCorrectionTest, MasoniteShortPieceIsUnbiased) {
  const Means m = MeanFits(ArParams{{1.61, -0.73}, 0.16}, 0.0);
  EXPECT_NEAR(m.corrected_a1, 1.61, kMeanTolerance);
  EXPECT_NEAR(m.corrected_a2, -0.73, kMeanTolerance);
  EXPECT_EQ(m.corrected_stationary, kSeeds);
  EXPECT_NEAR(m.corrected_sigma, 0.16, 0.16 * kSigmaMeanTolerance);
}

TEST(ArBiasCorrectionTest, RubberWithSensorNoiseIsUnbiased) {
  // 0.05 N of white noise on a process of std ~0.14 N: the noise-aware fit
  // and its replicates carry the same noise.
  const Means m = MeanFits(ArParams{{0.60, 0.25}, 0.11}, 0.05);
  EXPECT_NEAR(m.corrected_a1, 0.60, kMeanTolerance);
  EXPECT_NEAR(m.corrected_a2, 0.25, kMeanTolerance);
  EXPECT_NEAR(m.corrected_sigma, 0.11, 0.11 * kSigmaMeanTolerance);
}

TEST(ArBiasCorrectionTest, DeterministicForASeed) {
  const Eigen::VectorXd x = SimulateRoughness(ArParams{{0.6, 0.25}, 0.11}, 80, 5);
  ArFitOptions options;
  options.bias_replicates = 16;
  options.bias_seed = 3;
  const absl::StatusOr<ArFit> a = FitAutoregressive(x, options);
  const absl::StatusOr<ArFit> b = FitAutoregressive(x, options);
  ASSERT_TRUE(a.ok() && b.ok());
  EXPECT_EQ(a->a, b->a);
  options.bias_replicates = 0;
  const absl::StatusOr<ArFit> raw = FitAutoregressive(x, options);
  ASSERT_TRUE(raw.ok());
  EXPECT_NE(a->a, raw->a);
}

TEST(ArBiasCorrectionTest, TheCorrectedModelImpliesTheTrueProcessVariance) {
  // A renderer plays sigma through the impulse response of a, so the pair
  // must give the texture's amplitude, sigma^2 / prod(1 - k^2). A short
  // detrended piece shows about half of it (the raw fits' median below);
  // keeping that implied variance through the correction (the old rule) read
  // sigma 27 % low (0.080 for 0.11). Medians over the 200 seeds of 2 x 50
  // points of MeanFits; tolerance 7.5 %: ~35 % spread per seed / sqrt(200)
  // x 3, rounded up.
  const ArParams truth{{0.60, 0.25}, 0.11};
  const double true_variance = ArProcessVariance(truth.a, truth.sigma);
  const Means m = MeanFits(truth, 0.0);
  std::printf("process variance: truth %.5f, raw fits' median %.5f, corrected %.5f\n", true_variance,
              m.raw_variance_median, m.corrected_variance_median);
  EXPECT_LT(m.raw_variance_median, (1.0 - 0.075) * true_variance);
  EXPECT_NEAR(m.corrected_variance_median, true_variance, 0.075 * true_variance);
}

TEST(ArBiasCorrectionTest, CorrectionIsShrunkToStayStationary) {
  // Roots of modulus sqrt(0.95): a full correction by this bias would leave
  // the unit circle.
  const std::vector<double> a = {1.9, -0.95};
  const std::vector<double> bias = {-0.2, 0.1};
  const std::vector<double> corrected = ApplyArBiasCorrection(a, bias);
  EXPECT_LT(ArLargestRootModulus(corrected), 1.0);
  EXPECT_GT(corrected[0], a[0]);  // still moved towards the correction
}

TEST(ArBiasCorrectionTest, RejectsBadReplicateCounts) {
  const Eigen::VectorXd x = SimulateRoughness(ArParams{{0.6, 0.25}, 0.11}, 80, 5);
  ArFitOptions options;
  options.bias_replicates = -1;
  EXPECT_THAT(FitAutoregressive(x, options), StatusIs(absl::StatusCode::kInvalidArgument));
  options.bias_replicates = 10001;
  EXPECT_THAT(FitAutoregressive(x, options), StatusIs(absl::StatusCode::kInvalidArgument));
}

// Every random stream of 10000 replicates of 4 segments (the noise and each
// texture) has its own seed, for two bias seeds. The old arithmetic seeded
// replicate r's first texture with replicate r + 3959's noise seed.
TEST(ArBiasCorrectionTest, ReplicateStreamsNeverShareASeed) {
  std::set<std::uint64_t> seeds;
  int streams = 0;
  for (std::uint64_t bias_seed : {1ULL, 2ULL}) {
    for (int r = 0; r < 10000; ++r) {
      for (int stream = 0; stream <= 4; ++stream, ++streams) seeds.insert(BiasReplicateSeed(bias_seed, r, stream));
    }
  }
  EXPECT_EQ(seeds.size(), static_cast<std::size_t>(streams));
}

// The piece seed is a function of the bit patterns alone (the same on every
// platform) and tells apart pieces that std::hash-and-shift could confuse:
// swapped values and equal mu at different starts.
TEST(ArBiasCorrectionTest, PieceSeedsAreDistinctAndPortable) {
  EXPECT_EQ(BiasSeedFromData(0.5, 10.0),
            SplitMix64(SplitMix64(0x3fe0000000000000ULL) ^ 0x4024000000000000ULL));  // IEEE 754 bits of 0.5, 10
  EXPECT_NE(BiasSeedFromData(0.5, 10.0), BiasSeedFromData(10.0, 0.5));
  EXPECT_NE(BiasSeedFromData(0.5, 10.0), BiasSeedFromData(0.5, 15.0));
}

}  // namespace
}  // namespace surfmap
