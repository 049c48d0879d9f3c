#include "server/estimate/roughness.h"

#include <cmath>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include <Eigen/Dense>
#include <gtest/gtest.h>
#include "server/estimate/ar_autocorrelation.h"
#include "server/estimate/ar_roots.h"

namespace surfmap {
namespace {

// gmock is not linked into the module tests; a substring check that prints both.
::testing::AssertionResult HasSubstr(const std::string& text, const std::string& part) {
  if (text.find(part) != std::string::npos) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "\"" << text << "\" does not contain \"" << part << "\"";
}

// The paper's fits (Lloyd & Pai 2001): real roots 0.883, -0.283 for rubber; a
// complex pair of modulus sqrt(0.73) = 0.854 for masonite.
const ArParams kRubber{{0.60, 0.25}, 0.11};
const ArParams kMasonite{{1.61, -0.73}, 0.16};

// Closed forms for AR(2) with complex roots r e^(+-i theta): r = sqrt(-a2),
// cos theta = a1 / (2 r).
double Ar2RootAngle(double a1, double a2) { return std::acos(a1 / (2.0 * std::sqrt(-a2))); }

Eigen::VectorXd AddWhiteNoise(Eigen::VectorXd x, double noise_std, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> noise(0.0, noise_std);
  for (Eigen::Index i = 0; i < x.size(); ++i) x(i) += noise(rng);
  return x;
}

struct RefitCase {
  const char* name;
  ArParams truth;
  int n;
  ArMethod method;
};

std::string CaseName(const ::testing::TestParamInfo<RefitCase>& info) {
  return std::string(info.param.name) + "_n" + std::to_string(info.param.n) +
         (info.param.method == ArMethod::kBurg ? "_burg" : "_ls");
}

class RefitTest : public ::testing::TestWithParam<RefitCase> {};

// One fixed seed per case. Tolerances: |error| < 4 standard errors (measured
// over 50 seeds the largest |error| / stderr was 3.4); sigma within 10%, about
// 2 standard errors of an innovation std at n = 200 (1/sqrt(2n) = 5%) and 6 at
// n = 2000.
TEST_P(RefitTest, RecoversParametersWithinStandardErrors) {
  const RefitCase& c = GetParam();
  const Eigen::VectorXd x = SimulateRoughness(c.truth, c.n, /*seed=*/20010521);
  ArFitOptions options;
  options.method = c.method;
  const auto fit = FitAutoregressive(x, options);
  ASSERT_TRUE(fit.ok()) << fit.status();
  ASSERT_EQ(fit->a.size(), 2u);
  ASSERT_EQ(fit->a_stderr.size(), 2u);
  EXPECT_EQ(fit->n, c.n);
  for (int i = 0; i < 2; ++i) {
    // Asymptotic stderr of AR(2): sqrt((1 - a2^2) / n) for both coefficients.
    const double expected_stderr = std::sqrt((1.0 - c.truth.a[1] * c.truth.a[1]) / c.n);
    EXPECT_NEAR(fit->a_stderr[i], expected_stderr, 0.25 * expected_stderr) << "a" << i + 1;
    EXPECT_LT(std::abs(fit->a[i] - c.truth.a[i]), 4.0 * fit->a_stderr[i]) << "a" << i + 1;
  }
  EXPECT_NEAR(fit->sigma / c.truth.sigma, 1.0, 0.10);
  EXPECT_TRUE(fit->stationary);
  const std::vector<double> k = ArToReflection(fit->a);
  ASSERT_EQ(fit->reflection.size(), 2u);
  EXPECT_DOUBLE_EQ(fit->reflection[0], k[0]);
  EXPECT_DOUBLE_EQ(fit->reflection[1], k[1]);
  EXPECT_FALSE(fit->below_noise_floor);
}

// Over 50 seeds the mean error must vanish to within 4 standard errors of the
// mean (stderr / sqrt(50)); the O(1/n) small-sample bias of Burg and least
// squares (about 0.01 at n = 200) is below that. Same for sigma with the
// relative stderr 1/sqrt(2n).
TEST_P(RefitTest, UnbiasedOverFiftySeeds) {
  const RefitCase& c = GetParam();
  constexpr int kSeeds = 50;
  ArFitOptions options;
  options.method = c.method;
  double mean_error[2] = {0.0, 0.0};
  double mean_stderr[2] = {0.0, 0.0};
  double mean_sigma_ratio = 0.0;
  for (int seed = 0; seed < kSeeds; ++seed) {
    const auto fit = FitAutoregressive(SimulateRoughness(c.truth, c.n, 7000 + seed), options);
    ASSERT_TRUE(fit.ok()) << fit.status();
    for (int i = 0; i < 2; ++i) {
      mean_error[i] += (fit->a[i] - c.truth.a[i]) / kSeeds;
      mean_stderr[i] += fit->a_stderr[i] / kSeeds;
    }
    mean_sigma_ratio += fit->sigma / c.truth.sigma / kSeeds;
  }
  for (int i = 0; i < 2; ++i) {
    EXPECT_LT(std::abs(mean_error[i]), 4.0 * mean_stderr[i] / std::sqrt(kSeeds)) << "a" << i + 1;
  }
  EXPECT_NEAR(mean_sigma_ratio, 1.0, 4.0 / std::sqrt(2.0 * c.n) / std::sqrt(kSeeds));
}

INSTANTIATE_TEST_SUITE_P(
    PaperModels, RefitTest,
    ::testing::Values(RefitCase{"rubber", kRubber, 200, ArMethod::kBurg},
                      RefitCase{"rubber", kRubber, 200, ArMethod::kLeastSquares},
                      RefitCase{"rubber", kRubber, 2000, ArMethod::kBurg},
                      RefitCase{"rubber", kRubber, 2000, ArMethod::kLeastSquares},
                      RefitCase{"masonite", kMasonite, 200, ArMethod::kBurg},
                      RefitCase{"masonite", kMasonite, 200, ArMethod::kLeastSquares},
                      RefitCase{"masonite", kMasonite, 2000, ArMethod::kBurg},
                      RefitCase{"masonite", kMasonite, 2000, ArMethod::kLeastSquares}),
    CaseName);

TEST(FitAutoregressiveTest, ExplosiveSeriesFittedByLeastSquaresIsNonStationary) {
  // x(t) = 1.2 x(t-1) + 0.1 x(t-2) + e(t): roots 1.278 and -0.078.
  std::mt19937_64 rng(42);
  std::normal_distribution<double> innovation(0.0, 1.0);
  Eigen::VectorXd x(200);
  double x1 = 0.0, x2 = 0.0;
  for (Eigen::Index t = 0; t < x.size(); ++t) {
    x(t) = 1.2 * x1 + 0.1 * x2 + innovation(rng);
    x2 = x1;
    x1 = x(t);
  }
  ArFitOptions options;
  options.method = ArMethod::kLeastSquares;
  const auto fit = FitAutoregressive(x, options);
  ASSERT_TRUE(fit.ok()) << fit.status();
  EXPECT_FALSE(fit->stationary);
  // After mean removal the growth c 1.278^t - mean is fitted exactly by roots
  // 1.278 and 1 (the removed mean acts as a unit root).
  EXPECT_NEAR(ArLargestRootModulus(fit->a), 1.278, 0.01);
  bool some_reflection_outside = false;
  for (double k : fit->reflection) some_reflection_outside |= std::abs(k) >= 1.0 - 1e-9;
  EXPECT_TRUE(some_reflection_outside);

  // Burg cannot return a non-stationary model (|k| <= 1 by construction).
  options.method = ArMethod::kBurg;
  const auto burg = FitAutoregressive(x, options);
  ASSERT_TRUE(burg.ok()) << burg.status();
  EXPECT_TRUE(burg->stationary);
}

// Masonite plus white sensor noise of std 0.1 (variance 0.01 against a process
// variance of 0.41). The naive fit is biased by about (-0.32, +0.31); the
// noise-aware fit must remove that bias.
TEST(FitAutoregressiveTest, NoiseAwareFitRemovesNoiseBias) {
  constexpr int kSeeds = 20;
  constexpr int kN = 2000;
  constexpr double kNoiseStd = 0.1;
  for (ArMethod method : {ArMethod::kBurg, ArMethod::kLeastSquares}) {
    SCOPED_TRACE(method == ArMethod::kBurg ? "burg" : "least squares");
    double naive_abs_error[2] = {0, 0}, aware_abs_error[2] = {0, 0}, aware_error[2] = {0, 0};
    double naive_sigma = 0.0, aware_sigma = 0.0;
    for (int seed = 0; seed < kSeeds; ++seed) {
      const Eigen::VectorXd x =
          AddWhiteNoise(SimulateRoughness(kMasonite, kN, 300 + seed), kNoiseStd, 900 + seed);
      ArFitOptions options;
      options.method = method;
      const auto naive = FitAutoregressive(x, options);
      options.noise_variance = kNoiseStd * kNoiseStd;
      const auto aware = FitAutoregressive(x, options);
      ASSERT_TRUE(naive.ok() && aware.ok());
      EXPECT_FALSE(aware->below_noise_floor);
      EXPECT_TRUE(aware->stationary);
      for (int i = 0; i < 2; ++i) {
        naive_abs_error[i] += std::abs(naive->a[i] - kMasonite.a[i]) / kSeeds;
        aware_abs_error[i] += std::abs(aware->a[i] - kMasonite.a[i]) / kSeeds;
        aware_error[i] += (aware->a[i] - kMasonite.a[i]) / kSeeds;
      }
      naive_sigma += naive->sigma / kSeeds;
      aware_sigma += aware->sigma / kSeeds;
      EXPECT_NEAR(aware->variance, naive->variance - kNoiseStd * kNoiseStd, 1e-12);
    }
    for (int i = 0; i < 2; ++i) {
      SCOPED_TRACE(i == 0 ? "a1" : "a2");
      EXPECT_GT(naive_abs_error[i], 0.25);
      // Measured: mean |error| 0.025, mean error 0.004 (stderr of the mean ~0.007).
      EXPECT_LT(aware_abs_error[i], 0.05);
      EXPECT_LT(std::abs(aware_error[i]), 0.02);
      EXPECT_LT(aware_abs_error[i], naive_abs_error[i] / 5.0);
    }
    EXPECT_GT(naive_sigma, 0.2);  // noise inflates the innovation
    EXPECT_NEAR(aware_sigma, kMasonite.sigma, 0.1 * kMasonite.sigma);
  }
}

// A weak texture (ABS: a1 0.9, a2 -0.25, sigma 0.035, process variance
// 2.7e-3) under noise that is not white: MA(1) noise e(t) + 0.8 e(t-1) of
// std 0.015 per term (autocovariance 3.7e-4, 1.8e-4 at lags 0, 1). Taken as
// white of its lag-0 variance, the correction removes the wrong share of the
// lag-1 moment: measured mean errors +0.34 / -0.33. Given its autocovariance,
// both estimators are unbiased: measured -0.005 / +0.002 (stderr of the mean
// over 20 seeds x 2000 samples ~0.005).
TEST(FitAutoregressiveTest, ColouredNoiseIsRemovedWithItsAutocovariance) {
  const ArParams abs{{0.9, -0.25}, 0.035};
  constexpr int kSeeds = 20;
  constexpr int kN = 2000;
  constexpr double kStd = 0.015, kTheta = 0.8;
  const std::vector<double> noise{kStd * kStd * (1.0 + kTheta * kTheta), kStd * kStd * kTheta};
  for (ArMethod method : {ArMethod::kBurg, ArMethod::kLeastSquares}) {
    SCOPED_TRACE(method == ArMethod::kBurg ? "burg" : "least squares");
    double white_error[2] = {0, 0}, coloured_error[2] = {0, 0}, coloured_sigma = 0.0;
    for (int seed = 0; seed < kSeeds; ++seed) {
      Eigen::VectorXd x = SimulateRoughness(abs, kN, 400 + seed);
      std::mt19937_64 rng(1000 + seed);
      std::normal_distribution<double> gauss(0.0, kStd);
      double previous = gauss(rng);
      for (Eigen::Index i = 0; i < x.size(); ++i) {
        const double e = gauss(rng);
        x(i) += e + kTheta * previous;
        previous = e;
      }
      ArFitOptions options;
      options.method = method;
      options.noise_variance = noise[0];
      const auto white = FitAutoregressive(x, options);
      options.noise_variance = 0.0;
      options.noise_autocovariance = noise;
      const auto coloured = FitAutoregressive(x, options);
      ASSERT_TRUE(white.ok() && coloured.ok());
      EXPECT_FALSE(coloured->below_noise_floor);
      EXPECT_NEAR(coloured->variance, white->variance, 1e-15);  // lag 0 plays the same part
      for (int i = 0; i < 2; ++i) {
        white_error[i] += (white->a[i] - abs.a[i]) / kSeeds;
        coloured_error[i] += (coloured->a[i] - abs.a[i]) / kSeeds;
      }
      coloured_sigma += coloured->sigma / kSeeds;
    }
    EXPECT_GT(white_error[0], 0.2);
    EXPECT_LT(white_error[1], -0.2);
    for (int i = 0; i < 2; ++i) EXPECT_LT(std::abs(coloured_error[i]), 0.02) << "a" << i + 1;
    EXPECT_NEAR(coloured_sigma, abs.sigma, 0.05 * abs.sigma);
  }
}

// White noise given as an autocovariance of one lag is the same fit as
// noise_variance, to the last bit of each estimator's arithmetic.
TEST(FitAutoregressiveTest, WhiteNoiseAutocovarianceEqualsNoiseVariance) {
  const Eigen::VectorXd x = AddWhiteNoise(SimulateRoughness(kMasonite, 1500, 77), 0.1, 78);
  for (ArMethod method : {ArMethod::kBurg, ArMethod::kLeastSquares}) {
    ArFitOptions variance;
    variance.method = method;
    variance.noise_variance = 0.01;
    ArFitOptions autocovariance = variance;
    autocovariance.noise_variance = 0.0;
    autocovariance.noise_autocovariance = {0.01, 0.0, 0.0};
    const auto a = FitAutoregressive(x, variance);
    const auto b = FitAutoregressive(x, autocovariance);
    ASSERT_TRUE(a.ok() && b.ok());
    for (int i = 0; i < 2; ++i) EXPECT_NEAR(a->a[i], b->a[i], 1e-12);
    EXPECT_NEAR(a->sigma, b->sigma, 1e-12);
  }
}

TEST(FitAutoregressiveTest, TextureBelowNoiseFloorIsFlaggedButFitted) {
  // A series that is nothing but the sensor noise itself.
  const Eigen::VectorXd x = AddWhiteNoise(Eigen::VectorXd::Zero(500), 0.1, 5);
  for (ArMethod method : {ArMethod::kBurg, ArMethod::kLeastSquares}) {
    ArFitOptions options;
    options.method = method;
    options.noise_variance = 0.01;
    const auto fit = FitAutoregressive(x, options);
    ASSERT_TRUE(fit.ok()) << fit.status();
    EXPECT_TRUE(fit->below_noise_floor);
    EXPECT_EQ(fit->a.size(), 2u);
    EXPECT_GT(fit->sigma, 0.0);
  }
  // A small noise against masonite is not flagged.
  ArFitOptions options;
  options.noise_variance = 1e-4;
  const auto fit = FitAutoregressive(SimulateRoughness(kMasonite, 500, 6), options);
  ASSERT_TRUE(fit.ok()) << fit.status();
  EXPECT_FALSE(fit->below_noise_floor);
}

TEST(FitAutoregressiveTest, SingleSeriesEqualsOneSegment) {
  const Eigen::VectorXd x = SimulateRoughness(kMasonite, 240, 11);
  for (ArMethod method : {ArMethod::kBurg, ArMethod::kLeastSquares}) {
    ArFitOptions options;
    options.method = method;
    const auto single = FitAutoregressive(x, options);
    const auto segments = FitAutoregressive(std::vector<Eigen::VectorXd>{x}, options);
    ASSERT_TRUE(single.ok() && segments.ok());
    EXPECT_EQ(single->a, segments->a);
    EXPECT_EQ(single->sigma, segments->sigma);
    EXPECT_EQ(single->acf, segments->acf);
  }
}

TEST(FitAutoregressiveTest, BurgOrderOneSumsOverSegments) {
  // Known answer: k1 = 2 sum x(t) x(t-1) / sum (x(t)^2 + x(t-1)^2), both sums
  // over every segment, pairs inside a segment only, each segment's mean removed.
  std::vector<Eigen::VectorXd> segments{SimulateRoughness({{0.7}, 1.0}, 50, 1),
                                        SimulateRoughness({{0.7}, 1.0}, 35, 2)};
  segments[1].array() += 3.0;  // a different offset per pass must not matter
  double numerator = 0.0, denominator = 0.0;
  for (const auto& segment : segments) {
    const Eigen::VectorXd x = segment.array() - segment.mean();
    for (Eigen::Index t = 1; t < x.size(); ++t) {
      numerator += x(t) * x(t - 1);
      denominator += x(t) * x(t) + x(t - 1) * x(t - 1);
    }
  }
  ArFitOptions options;
  options.order = 1;
  const auto fit = FitAutoregressive(segments, options);
  ASSERT_TRUE(fit.ok()) << fit.status();
  EXPECT_NEAR(fit->a[0], 2.0 * numerator / denominator, 1e-12);
  EXPECT_EQ(fit->n, 85);
}

TEST(FitAutoregressiveTest, LeastSquaresStacksRowsPerSegment) {
  // Known answer: OLS on the rows of each segment, never a row whose lags
  // reach into the other segment.
  std::vector<Eigen::VectorXd> segments{SimulateRoughness(kMasonite, 60, 3),
                                        SimulateRoughness(kMasonite, 45, 4)};
  segments[0].array() -= 1.0;
  const int p = 2;
  Eigen::MatrixXd regressors(60 - p + 45 - p, p);
  Eigen::VectorXd target(regressors.rows());
  Eigen::Index row = 0;
  for (const auto& segment : segments) {
    const Eigen::VectorXd x = segment.array() - segment.mean();
    for (Eigen::Index t = p; t < x.size(); ++t, ++row) {
      target(row) = x(t);
      regressors(row, 0) = x(t - 1);
      regressors(row, 1) = x(t - 2);
    }
  }
  const Eigen::Vector2d expected = regressors.colPivHouseholderQr().solve(target);
  ArFitOptions options;
  options.method = ArMethod::kLeastSquares;
  const auto fit = FitAutoregressive(segments, options);
  ASSERT_TRUE(fit.ok()) << fit.status();
  EXPECT_NEAR(fit->a[0], expected(0), 1e-10);
  EXPECT_NEAR(fit->a[1], expected(1), 1e-10);
  const double rss = (target - regressors * expected).squaredNorm();
  EXPECT_NEAR(fit->sigma, std::sqrt(rss / (regressors.rows() - p)), 1e-10);
}

TEST(FitAutoregressiveTest, ForwardAndReversePassesTogetherFitTheProcess) {
  // Two 1000-sample passes of masonite: the combined fit is as good as one of
  // 2000 samples (stderr ~ sqrt((1 - a2^2) / 2000) = 0.015).
  for (ArMethod method : {ArMethod::kBurg, ArMethod::kLeastSquares}) {
    ArFitOptions options;
    options.method = method;
    const auto fit = FitAutoregressive(
        {SimulateRoughness(kMasonite, 1000, 21), SimulateRoughness(kMasonite, 1000, 22)}, options);
    ASSERT_TRUE(fit.ok()) << fit.status();
    EXPECT_EQ(fit->n, 2000);
    for (int i = 0; i < 2; ++i) {
      EXPECT_NEAR(fit->a_stderr[i], 0.0153, 0.002);
      EXPECT_LT(std::abs(fit->a[i] - kMasonite.a[i]), 4.0 * fit->a_stderr[i]);
    }
    EXPECT_NEAR(fit->sigma / kMasonite.sigma, 1.0, 0.05);
  }
}

TEST(FitAutoregressiveTest, NoiseAwareFitOverTwoPasses) {
  // Each pass carries its own white noise (std 0.1) on the same texture.
  for (ArMethod method : {ArMethod::kBurg, ArMethod::kLeastSquares}) {
    const std::vector<Eigen::VectorXd> passes{
        AddWhiteNoise(SimulateRoughness(kMasonite, 1000, 31), 0.1, 41),
        AddWhiteNoise(SimulateRoughness(kMasonite, 1000, 32), 0.1, 42)};
    ArFitOptions options;
    options.method = method;
    const auto naive = FitAutoregressive(passes, options);
    options.noise_variance = 0.01;
    const auto aware = FitAutoregressive(passes, options);
    ASSERT_TRUE(naive.ok() && aware.ok());
    for (int i = 0; i < 2; ++i) {
      EXPECT_GT(std::abs(naive->a[i] - kMasonite.a[i]), 0.2);
      // The noise correction roughly doubles the spread (0.025 mean |error| at
      // n = 2000 over 20 seeds, see NoiseAwareFitRemovesNoiseBias).
      EXPECT_LT(std::abs(aware->a[i] - kMasonite.a[i]), 0.1);
    }
    EXPECT_NEAR(aware->sigma / kMasonite.sigma, 1.0, 0.1);
  }
}

TEST(FitAutoregressiveTest, HigherOrderOnAr2DataFindsNoExtraTerms) {
  ArFitOptions options;
  options.order = 4;
  const auto fit = FitAutoregressive(SimulateRoughness(kMasonite, 4000, 8), options);
  ASSERT_TRUE(fit.ok()) << fit.status();
  ASSERT_EQ(fit->a.size(), 4u);
  EXPECT_LT(std::abs(fit->a[0] - 1.61), 4.0 * fit->a_stderr[0]);
  EXPECT_LT(std::abs(fit->a[1] + 0.73), 4.0 * fit->a_stderr[1]);
  EXPECT_LT(std::abs(fit->a[2]), 4.0 * fit->a_stderr[2]);
  EXPECT_LT(std::abs(fit->a[3]), 4.0 * fit->a_stderr[3]);
}

TEST(DominantWavelengthTest, MasoniteMatchesClosedFormFromRoots) {
  const double step = 0.1;
  // True model: theta = acos(1.61 / (2 sqrt(0.73))) = 0.3417, 18.39 steps.
  const double closed_form = 2.0 * std::numbers::pi * step / Ar2RootAngle(1.61, -0.73);
  EXPECT_NEAR(closed_form, 1.8387, 1e-3);
  const auto steps = ArDominantWavelengthSteps(kMasonite.a);
  ASSERT_TRUE(steps.has_value());
  EXPECT_NEAR(*steps * step, closed_form, 1e-9);

  ArFitOptions options;
  options.step_mm = step;
  const auto fit = FitAutoregressive(SimulateRoughness(kMasonite, 2000, 12), options);
  ASSERT_TRUE(fit.ok()) << fit.status();
  ASSERT_TRUE(fit->dominant_wavelength_mm.has_value());
  // Exactly the closed form of the fitted roots...
  EXPECT_NEAR(*fit->dominant_wavelength_mm,
              2.0 * std::numbers::pi * step / Ar2RootAngle(fit->a[0], fit->a[1]), 1e-9);
  // ...and near the truth: with a stderr of 0.015 on a1, a2 the angle moves by
  // about 3%; allow 10%.
  EXPECT_NEAR(*fit->dominant_wavelength_mm, closed_form, 0.1 * closed_form);
}

TEST(DominantWavelengthTest, NoneForRealRootsOrSpectrumPeakAtZero) {
  EXPECT_FALSE(ArDominantWavelengthSteps(kRubber.a).has_value());  // roots 0.883, -0.283
  const auto fit = FitAutoregressive(SimulateRoughness(kRubber, 2000, 13), ArFitOptions{});
  ASSERT_TRUE(fit.ok()) << fit.status();
  EXPECT_FALSE(fit->dominant_wavelength_mm.has_value());
  // Complex roots (0.85^2 < 4 * 0.2) but a spectrum that still peaks at zero
  // frequency: cos w* = a1 (a2 - 1) / (4 a2) = 1.275 > 1.
  EXPECT_FALSE(ArDominantWavelengthSteps({0.85, -0.2}).has_value());
  // Complex roots with an interior peak: cos w* = 0.15.
  EXPECT_TRUE(ArDominantWavelengthSteps({0.2, -0.5}).has_value());
  // A negative real root (alternating texture at the grid frequency): none.
  EXPECT_FALSE(ArDominantWavelengthSteps({-0.8}).has_value());
}

TEST(AutocorrelationTest, Ar1MatchesGeometricDecay) {
  constexpr double kA = 0.8;
  constexpr int kN = 20000;
  const Eigen::VectorXd x = SimulateRoughness({{kA}, 1.0}, kN, 14);
  const Eigen::VectorXd r = Autocorrelation(x, 10);
  ASSERT_EQ(r.size(), 11);
  EXPECT_DOUBLE_EQ(r(0), 1.0);
  // Bartlett: var r(k) <= (1 + a^2) / ((1 - a^2) n), stderr <= 0.015 here.
  const double bound = 4.0 * std::sqrt((1 + kA * kA) / ((1 - kA * kA) * kN));
  for (int k = 1; k <= 10; ++k) EXPECT_NEAR(r(k), std::pow(kA, k), bound) << "lag " << k;
}

TEST(AutocorrelationTest, DecayLengthMatchesMinusStepOverLogA) {
  constexpr double kA = 0.8;
  constexpr double kStep = 0.1;
  constexpr int kN = 20000;
  ArFitOptions options;
  options.order = 1;
  options.step_mm = kStep;
  const auto fit = FitAutoregressive(SimulateRoughness({{kA}, 1.0}, kN, 15), options);
  ASSERT_TRUE(fit.ok()) << fit.status();
  // Exact for the fitted model (its ACF is a^k, interpolated log-linearly)...
  EXPECT_NEAR(fit->acf_decay_mm, -kStep / std::log(fit->a[0]), 1e-9);
  // ...and within 4 stderr of the truth 0.448 mm: d(decay)/da = step / (a ln^2 a),
  // stderr(a) = sqrt((1 - a^2) / n).
  const double decay_stderr = kStep / (kA * std::pow(std::log(kA), 2)) * std::sqrt((1 - kA * kA) / kN);
  EXPECT_NEAR(fit->acf_decay_mm, -kStep / std::log(kA), 4.0 * decay_stderr);
  // The sample ACF crosses 1/e at the same place (to its own sampling error).
  const auto sample_lags = CorrelationLengthLags(fit->acf);
  ASSERT_TRUE(sample_lags.has_value());
  EXPECT_NEAR(*sample_lags * kStep, -kStep / std::log(kA), 0.1 * -kStep / std::log(kA));
}

TEST(AutocorrelationTest, DefaultLagsAndEdgeCases) {
  const auto fit = FitAutoregressive(SimulateRoughness(kRubber, 200, 16), ArFitOptions{});
  ASSERT_TRUE(fit.ok()) << fit.status();
  EXPECT_EQ(fit->acf.size(), 51u);  // min(200 / 4, 200) + 1
  EXPECT_DOUBLE_EQ(fit->acf[0], 1.0);
  ArFitOptions options;
  options.acf_max_lag = 500;  // clamped to the series length - 1
  const auto clamped = FitAutoregressive(SimulateRoughness(kRubber, 100, 16), options);
  ASSERT_TRUE(clamped.ok()) << clamped.status();
  EXPECT_EQ(clamped->acf.size(), 100u);

  EXPECT_EQ(Autocorrelation(Eigen::VectorXd(), 5).size(), 0);
  const Eigen::VectorXd constant = Eigen::VectorXd::Constant(10, 2.5);
  const Eigen::VectorXd r = Autocorrelation(constant, 3);
  ASSERT_EQ(r.size(), 4);
  EXPECT_EQ(r(0), 1.0);
  EXPECT_EQ(r.tail(3).norm(), 0.0);
  EXPECT_EQ(Autocorrelation(Eigen::VectorXd::LinSpaced(5, 0, 1), 99).size(), 5);  // clamped to n - 1
  EXPECT_EQ(Autocorrelation(Eigen::VectorXd::LinSpaced(5, 0, 1), -3).size(), 1);
}

TEST(AutocorrelationTest, CorrelationLengthKnownAnswers) {
  std::vector<double> geometric;
  for (int k = 0; k < 30; ++k) geometric.push_back(std::pow(0.5, k));
  EXPECT_NEAR(*CorrelationLengthLags(geometric), 1.0 / std::log(2.0), 1e-12);
  // A later excursion above 1/e (a periodic texture) moves the length out.
  // |acf| is last >= 1/e at lag 2 (0.5), then 0.1.
  const std::vector<double> revisits = {1.0, 0.2, -0.5, 0.1, 0.0};
  EXPECT_NEAR(*CorrelationLengthLags(revisits),
              2.0 + (std::log(0.5) + 1.0) / (std::log(0.5) - std::log(0.1)), 1e-12);
  EXPECT_FALSE(CorrelationLengthLags({1.0, 0.9, 0.8}).has_value());  // never settles
  EXPECT_FALSE(CorrelationLengthLags({}).has_value());
  EXPECT_NEAR(*CorrelationLengthLags({1.0, 0.0}), 1.0 - std::exp(-1.0), 1e-12);  // linear at a zero
}

TEST(AutocorrelationTest, ModelAutocorrelationKnownAnswers) {
  // AR(2): rho1 = a1 / (1 - a2), rho2 = a1 rho1 + a2, rho3 = a1 rho2 + a2 rho1.
  const std::vector<double> rho = ArModelAutocorrelation(kMasonite.a, 3);
  ASSERT_EQ(rho.size(), 4u);
  const double rho1 = 1.61 / 1.73;
  const double rho2 = 1.61 * rho1 - 0.73;
  EXPECT_DOUBLE_EQ(rho[0], 1.0);
  EXPECT_NEAR(rho[1], rho1, 1e-14);
  EXPECT_NEAR(rho[2], rho2, 1e-14);
  EXPECT_NEAR(rho[3], 1.61 * rho2 - 0.73 * rho1, 1e-14);
  EXPECT_TRUE(ArModelAutocorrelation({1.2, 0.1}, 5).empty());  // not stationary
  // Masonite's correlation length: |rho| last above 1/e at lag 3 (0.41), lag 4
  // is 0.16: 3 + ln(0.41 e) / ln(0.41 / 0.16), about 3.9 lags.
  const std::vector<double> long_rho = ArModelAutocorrelation(kMasonite.a, 200);
  const double expected =
      3.0 + (std::log(std::abs(long_rho[3])) + 1.0) /
                (std::log(std::abs(long_rho[3])) - std::log(std::abs(long_rho[4])));
  EXPECT_NEAR(*CorrelationLengthLags(long_rho), expected, 1e-12);
  EXPECT_NEAR(expected, 3.9, 0.1);
}

TEST(ReflectionTest, KnownAr2Values) {
  // k2 = a2, k1 = a1 / (1 - a2).
  const std::vector<double> k = ArToReflection(kMasonite.a);
  ASSERT_EQ(k.size(), 2u);
  EXPECT_NEAR(k[0], 1.61 / 1.73, 1e-14);
  EXPECT_NEAR(k[1], -0.73, 1e-14);
  const std::vector<double> rubber = ArToReflection(kRubber.a);
  EXPECT_NEAR(rubber[0], 0.8, 1e-14);
  EXPECT_NEAR(rubber[1], 0.25, 1e-14);
  // Non-stationary model: k1 = 1.2 / 0.9 > 1.
  const std::vector<double> explosive = ArToReflection({1.2, 0.1});
  EXPECT_GT(std::abs(explosive[0]), 1.0);
  EXPECT_EQ(ArToReflection({0.5}), std::vector<double>{0.5});
  EXPECT_TRUE(ArToReflection({}).empty());
}

TEST(ReflectionTest, RoundTripsAndStableModelsMapInsideUnitInterval) {
  std::mt19937_64 rng(77);
  std::uniform_real_distribution<double> uniform(-0.95, 0.95);
  for (int order = 1; order <= 20; ++order) {
    std::vector<double> k(order);
    for (double& km : k) km = uniform(rng);
    const std::vector<double> a = ReflectionToAr(k);
    ASSERT_EQ(a.size(), k.size());
    EXPECT_LT(ArLargestRootModulus(a), 1.0) << "order " << order;  // |k| < 1 => stable
    const std::vector<double> back = ArToReflection(a);
    for (int m = 0; m < order; ++m) EXPECT_NEAR(back[m], k[m], 1e-8) << "order " << order << " k" << m + 1;
    const std::vector<double> again = ReflectionToAr(back);
    for (int m = 0; m < order; ++m) EXPECT_NEAR(again[m], a[m], 1e-8);
  }
}

TEST(ProcessVarianceTest, KnownAnswersAndNonStationaryModels) {
  // AR(1): sigma^2 / (1 - a^2).
  EXPECT_DOUBLE_EQ(ArProcessVariance({0.5}, 1.0), 4.0 / 3.0);
  // AR(2): sigma^2 (1 - a2) / ((1 + a2) ((1 - a2)^2 - a1^2)), rubber 0.6 / 0.25.
  const double a1 = 0.6, a2 = 0.25, sigma = 0.11;
  EXPECT_NEAR(ArProcessVariance({a1, a2}, sigma),
              sigma * sigma * (1 - a2) / ((1 + a2) * ((1 - a2) * (1 - a2) - a1 * a1)), 1e-15);
  // And the simulated process has that variance (2e5 samples: ~1 % spread).
  const Eigen::VectorXd x = SimulateRoughness(ArParams{{a1, a2}, sigma}, 200000, 4);
  const double variance = (x.array() - x.mean()).square().mean();
  EXPECT_NEAR(variance, ArProcessVariance({a1, a2}, sigma), 0.05 * variance);
  EXPECT_TRUE(std::isinf(ArProcessVariance({1.2}, 1.0)));
  EXPECT_DOUBLE_EQ(ArProcessVariance({}, 2.0), 4.0);
}

TEST(SimulateRoughnessTest, SeededAndStationary) {
  const Eigen::VectorXd x = SimulateRoughness(kMasonite, 300, 1);
  EXPECT_EQ(x.size(), 300);
  EXPECT_EQ(x, SimulateRoughness(kMasonite, 300, 1));
  EXPECT_NE(x, SimulateRoughness(kMasonite, 300, 2));
  EXPECT_EQ(SimulateRoughness(kMasonite, 0, 1).size(), 0);
  EXPECT_EQ(SimulateRoughness(kMasonite, -5, 1).size(), 0);
  // AR(1) variance sigma^2 / (1 - a^2) = 2.78; relative stderr of the sample
  // variance sqrt(2 (1 + a^2) / ((1 - a^2) n)) = 2.1% at n = 20000.
  const Eigen::VectorXd y = SimulateRoughness({{0.8}, 1.0}, 20000, 3);
  const double variance = (y.array() - y.mean()).square().mean();
  EXPECT_NEAR(variance / (1.0 / 0.36), 1.0, 4 * 0.0213);
  // Burn-in: the first samples already have the stationary spread (not 0).
  double early = 0.0;
  for (int seed = 0; seed < 400; ++seed) {
    early += std::pow(SimulateRoughness({{0.8}, 1.0}, 1, seed)(0), 2) / 400;
  }
  EXPECT_NEAR(early / (1.0 / 0.36), 1.0, 0.3);  // 400 draws of a chi^2_1: stderr 7%
}

TEST(FitAutoregressiveErrorsTest, RejectsBadInputWithClearMessages) {
  ArFitOptions options;
  auto status_of = [&](const Eigen::VectorXd& x) { return FitAutoregressive(x, options).status(); };
  const Eigen::VectorXd good = SimulateRoughness(kRubber, 100, 1);

  auto s = status_of(good.head(11));
  EXPECT_EQ(s.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_TRUE(HasSubstr(std::string(s.message()), "needs at least 12"));
  EXPECT_TRUE(status_of(good.head(12)).ok());

  Eigen::VectorXd bad = good;
  bad(17) = std::nan("");
  s = status_of(bad);
  EXPECT_EQ(s.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_TRUE(HasSubstr(std::string(s.message()), "sample 17 is not finite"));
  bad(17) = INFINITY;
  EXPECT_TRUE(HasSubstr(std::string(status_of(bad).message()), "sample 17"));

  s = status_of(Eigen::VectorXd::Constant(50, 5.0));
  EXPECT_EQ(s.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_TRUE(HasSubstr(std::string(s.message()), "zero variance"));

  s = status_of(Eigen::VectorXd::LinSpaced(50, 0.0, 1e200));
  EXPECT_TRUE(HasSubstr(std::string(s.message()), "overflows"));

  for (int order : {0, 21, -1}) {
    options.order = order;
    s = status_of(good);
    EXPECT_EQ(s.code(), absl::StatusCode::kInvalidArgument);
    EXPECT_TRUE(HasSubstr(std::string(s.message()), "outside 1..20"));
  }
  options.order = 20;  // allowed, and 100 >= 4 * 21 samples
  EXPECT_TRUE(status_of(good).ok());
  options = {};
  for (double step : {0.0, -0.1, std::nan("")}) {
    options.step_mm = step;
    EXPECT_TRUE(HasSubstr(std::string(status_of(good).message()), "step_mm"));
  }
  options = {};
  options.noise_variance = -1.0;
  EXPECT_TRUE(HasSubstr(std::string(status_of(good).message()), "noise_variance"));
  options = {};
  options.acf_max_lag = -2;
  EXPECT_TRUE(HasSubstr(std::string(status_of(good).message()), "acf_max_lag"));

  options = {};
  s = FitAutoregressive(std::vector<Eigen::VectorXd>{}, options).status();
  EXPECT_TRUE(HasSubstr(std::string(s.message()), "no segments"));
  s = FitAutoregressive({good, good.head(2)}, options).status();
  EXPECT_TRUE(HasSubstr(std::string(s.message()), "segment 1 has 2 samples"));
  // 6 segments of 3 samples: 18 >= 12 samples but only 6 rows < 10.
  s = FitAutoregressive(std::vector<Eigen::VectorXd>(6, good.head(3)), options).status();
  EXPECT_TRUE(HasSubstr(std::string(s.message()), "6 lagged rows"));
  Eigen::VectorXd bad_reverse = good;
  bad_reverse(3) = NAN;
  s = FitAutoregressive({good, bad_reverse}, options).status();
  EXPECT_TRUE(HasSubstr(std::string(s.message()), "segment 1 sample 3 is not finite"));
}

TEST(ArFitOptionsTest, IsValidExplains) {
  ArFitOptions options;
  EXPECT_TRUE(options.IsValid(nullptr));
  options.order = 30;
  std::string why;
  EXPECT_FALSE(options.IsValid(&why));
  EXPECT_TRUE(HasSubstr(why, "order 30"));
  EXPECT_FALSE(options.IsValid(nullptr));

  ArFitOptions noise;
  noise.noise_variance = 0.01;
  noise.noise_autocovariance = {0.01};
  EXPECT_FALSE(noise.IsValid(&why));
  EXPECT_TRUE(HasSubstr(why, "both given")) << why;
  noise.noise_variance = 0.0;
  noise.noise_autocovariance = {0.01, 0.02};
  EXPECT_FALSE(noise.IsValid(&why));
  EXPECT_TRUE(HasSubstr(why, "lag 1 is 0.02")) << why;
  noise.noise_autocovariance = {-0.01};
  EXPECT_FALSE(noise.IsValid(&why));
  EXPECT_TRUE(HasSubstr(why, "lag 0 is -0.01")) << why;
  noise.noise_autocovariance = {0.01, std::nan("")};
  EXPECT_FALSE(noise.IsValid(&why));
  noise.noise_autocovariance.assign(65, 0.0);
  EXPECT_FALSE(noise.IsValid(&why));
  EXPECT_TRUE(HasSubstr(why, "65 lags")) << why;
  noise.noise_autocovariance = {0.01, -0.005};
  EXPECT_TRUE(noise.IsValid(&why)) << why;
}

}  // namespace
}  // namespace surfmap
