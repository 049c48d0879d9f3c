#include "server/estimate/roughness.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <string>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"
#include "server/estimate/ar_autocorrelation.h"
#include "server/estimate/ar_bias_correction.h"
#include "server/estimate/ar_burg.h"
#include "server/estimate/ar_least_squares.h"
#include "server/estimate/ar_roots.h"

namespace surfmap {
namespace {

constexpr int kMaxOrder = 20;
constexpr int kMaxBiasReplicates = 10000;
constexpr std::size_t kMaxNoiseLags = 64;
// The model ACF is followed until the dominant root has decayed by e^-30, far
// past any 1/e crossing; and never past this many lags (roots within ~3e-4 of
// the unit circle), where the correlation length is reported as a lower bound.
constexpr double kModelAcfEFoldings = 30.0;
constexpr int kModelAcfMaxLag = 100000;

// Zero variance up to rounding: mean removal of a constant series leaves
// residue of order eps * |value|.
bool IsZeroVariance(double variance, double mean_square) {
  return !(variance > 1e-24 * mean_square);
}

std::string SegmentName(std::size_t index, std::size_t count) {
  return count == 1 ? std::string("series") : absl::StrCat("segment ", index);
}

int DefaultAcfMaxLag(Eigen::Index n) {
  return static_cast<int>(std::min<Eigen::Index>(n / 4, 200));
}

double CorrelationLengthMm(const ArFit& fit, double largest_root_modulus, int acf_max_lag,
                           double step_mm) {
  const int p = static_cast<int>(fit.a.size());
  if (fit.stationary) {
    int lags = p + 1;
    if (largest_root_modulus > 0.0) {
      const double e_folding = -1.0 / std::log(largest_root_modulus);
      lags = static_cast<int>(std::min<double>(kModelAcfMaxLag, p + 1 + std::ceil(kModelAcfEFoldings * e_folding)));
    }
    const std::vector<double> model = ArModelAutocorrelation(fit.a, lags);
    if (!model.empty()) {
      return CorrelationLengthLags(model).value_or(static_cast<double>(lags)) * step_mm;
    }
  }
  return CorrelationLengthLags(fit.acf).value_or(static_cast<double>(acf_max_lag)) * step_mm;
}

}  // namespace

bool ArFitOptions::IsValid(std::string* why) const {
  std::string reason;
  if (order < 1 || order > kMaxOrder) {
    reason = absl::StrCat("order ", order, " is outside 1..", kMaxOrder);
  } else if (!std::isfinite(step_mm) || step_mm <= 0.0) {
    reason = absl::StrCat("step_mm ", step_mm, " must be a finite length > 0");
  } else if (!std::isfinite(noise_variance) || noise_variance < 0.0) {
    reason = absl::StrCat("noise_variance ", noise_variance, " must be finite and >= 0");
  } else if (!noise_autocovariance.empty() && noise_variance > 0.0) {
    reason = "noise_variance and noise_autocovariance are both given; give one";
  } else if (noise_autocovariance.size() > kMaxNoiseLags) {
    reason = absl::StrCat("noise_autocovariance has ", noise_autocovariance.size(), " lags; at most ",
                          kMaxNoiseLags);
  } else if (!std::isfinite(noise_floor_ratio) || noise_floor_ratio < 1.0) {
    reason = absl::StrCat("noise_floor_ratio ", noise_floor_ratio, " must be finite and >= 1");
  } else if (acf_max_lag < 0) {
    reason = absl::StrCat("acf_max_lag ", acf_max_lag, " must be >= 0 (0 = automatic)");
  } else if (bias_replicates < 0 || bias_replicates > kMaxBiasReplicates) {
    reason = absl::StrCat("bias_replicates ", bias_replicates, " is outside 0..", kMaxBiasReplicates);
  }
  for (std::size_t lag = 0; reason.empty() && lag < noise_autocovariance.size(); ++lag) {
    const double c = noise_autocovariance[lag];
    if (!std::isfinite(c) || (lag == 0 && c < 0.0) || (lag > 0 && std::abs(c) > noise_autocovariance[0])) {
      reason = absl::StrCat("noise_autocovariance lag ", lag, " is ", c,
                            "; lag 0 must be finite and >= 0 and no lag larger than lag 0 in size");
    }
  }
  if (reason.empty()) return true;
  if (why != nullptr) *why = std::move(reason);
  return false;
}

std::vector<double> ArFitOptions::NoiseAutocovariance() const {
  if (!noise_autocovariance.empty()) return noise_autocovariance;
  if (noise_variance > 0.0) return {noise_variance};
  return {};
}

absl::StatusOr<ArFit> FitAutoregressive(const Eigen::VectorXd& series, const ArFitOptions& options) {
  return FitAutoregressive(std::vector<Eigen::VectorXd>{series}, options);
}

absl::StatusOr<ArFit> FitAutoregressive(std::initializer_list<Eigen::VectorXd> segments,
                                        const ArFitOptions& options) {
  return FitAutoregressive(std::vector<Eigen::VectorXd>(segments), options);
}

absl::StatusOr<ArFit> FitAutoregressive(const std::vector<Eigen::VectorXd>& segments,
                                        const ArFitOptions& options) {
  std::string why;
  if (!options.IsValid(&why)) return absl::InvalidArgumentError(absl::StrCat("ArFitOptions: ", why));
  if (segments.empty()) return absl::InvalidArgumentError("no segments to fit an AR model to");
  const int p = options.order;

  Eigen::Index n_total = 0;
  Eigen::Index shortest = segments.front().size();
  for (std::size_t s = 0; s < segments.size(); ++s) {
    const Eigen::VectorXd& x = segments[s];
    for (Eigen::Index i = 0; i < x.size(); ++i) {
      if (!std::isfinite(x(i))) {
        return absl::InvalidArgumentError(absl::StrCat(SegmentName(s, segments.size()), " sample ", i,
                                                       " is not finite (", x(i), ")"));
      }
    }
    if (x.size() <= p) {
      return absl::InvalidArgumentError(absl::StrCat(SegmentName(s, segments.size()), " has ", x.size(),
                                                     " samples; AR(", p, ") needs more than ", p));
    }
    n_total += x.size();
    shortest = std::min(shortest, x.size());
  }
  if (n_total < 4 * (p + 1)) {
    return absl::InvalidArgumentError(absl::StrCat(segments.size() == 1 ? "series has " : "segments have ",
                                                   n_total, " samples; AR(", p, ") needs at least ",
                                                   4 * (p + 1), " (4 * (order + 1))"));
  }

  // Many short segments can pass the sample count but leave few regression
  // rows (each segment loses `order` to its lags): ask for as many rows as one
  // series of 4 * (order + 1) samples has.
  const Eigen::Index rows = n_total - static_cast<Eigen::Index>(segments.size()) * p;
  if (rows < 3 * p + 4) {
    return absl::InvalidArgumentError(absl::StrCat(
        "segments give ", rows, " lagged rows (sum of length - order); AR(", p, ") needs at least ",
        3 * p + 4, ", as many as one series of ", 4 * (p + 1), " samples"));
  }

  std::vector<Eigen::VectorXd> centered;
  centered.reserve(segments.size());
  double mean_square = 0.0;
  for (const auto& x : segments) {
    mean_square += x.squaredNorm();
    centered.push_back(x.array() - x.mean());
  }
  mean_square /= static_cast<double>(n_total);
  const Eigen::VectorXd lag0 = PooledAutocovariance(centered, 0);
  const double raw_variance = lag0(0);
  if (!std::isfinite(raw_variance) || !std::isfinite(mean_square)) {
    return absl::InvalidArgumentError(absl::StrCat(
        "series values are too large: their variance overflows (", raw_variance, ")"));
  }
  if (IsZeroVariance(raw_variance, mean_square)) {
    return absl::InvalidArgumentError(absl::StrCat(
        segments.size() == 1 ? "series has" : "segments have", " zero variance (",
        segments.size() == 1 ? "all samples equal" : "each segment constant", "); nothing to fit"));
  }

  ArFit fit;
  fit.n = static_cast<int>(n_total);
  const std::vector<double> noise = options.NoiseAutocovariance();
  const double noise_variance = noise.empty() ? 0.0 : noise[0];
  fit.below_noise_floor = noise_variance > 0.0 && raw_variance <= options.noise_floor_ratio * noise_variance;
  auto solve = [&](const std::vector<double>& correction) {
    return options.method == ArMethod::kBurg ? SolveBurg(centered, p, raw_variance, correction)
                                             : SolveLeastSquares(centered, p, correction);
  };
  ArSolution solution = solve(fit.below_noise_floor ? std::vector<double>{} : noise);
  if (solution.noise_correction_failed) {
    fit.below_noise_floor = true;
    solution = solve({});
  }
  fit.a = std::move(solution.a);
  fit.a_stderr = std::move(solution.a_stderr);
  fit.sigma = std::sqrt(std::max(0.0, solution.innovation_variance));
  fit.variance = std::max(0.0, raw_variance - noise_variance);

  double largest_root = ArLargestRootModulus(fit.a);
  if (options.bias_replicates > 0 && largest_root < 1.0 && !fit.below_noise_floor) {
    std::vector<int> lengths;
    lengths.reserve(segments.size());
    for (const auto& x : segments) lengths.push_back(static_cast<int>(x.size()));
    const ArBiasEstimate bias = EstimateArBias(fit.a, fit.sigma, lengths, options);
    if (bias.replicates_used > 0) {
      fit.a = ApplyArBiasCorrection(fit.a, bias.bias);
      largest_root = ArLargestRootModulus(fit.a);
      // sigma has its own small-sample bias (low, like the process variance
      // of a short detrended segment); corrected the same way. A correction
      // that would leave nothing (impossible unless the replicates disagree
      // wildly with the data) is not applied.
      if (fit.sigma - bias.sigma_bias > 0.0) fit.sigma -= bias.sigma_bias;
    }
  }
  fit.stationary = largest_root < 1.0;
  fit.reflection = ArToReflection(fit.a);

  int acf_max_lag = options.acf_max_lag > 0 ? options.acf_max_lag : DefaultAcfMaxLag(n_total);
  acf_max_lag = static_cast<int>(std::min<Eigen::Index>(acf_max_lag, shortest - 1));
  const Eigen::VectorXd autocovariance = PooledAutocovariance(centered, acf_max_lag);
  fit.acf.resize(autocovariance.size());
  for (Eigen::Index k = 0; k < autocovariance.size(); ++k) fit.acf[k] = autocovariance(k) / raw_variance;

  fit.acf_decay_mm = CorrelationLengthMm(fit, largest_root, acf_max_lag, options.step_mm);
  if (const auto steps = ArDominantWavelengthSteps(fit.a)) {
    fit.dominant_wavelength_mm = *steps * options.step_mm;
  }
  return fit;
}

Eigen::VectorXd Autocorrelation(const Eigen::VectorXd& series, int max_lag) {
  const Eigen::Index n = series.size();
  if (n == 0) return Eigen::VectorXd();
  max_lag = static_cast<int>(std::clamp<Eigen::Index>(max_lag, 0, n - 1));
  const std::vector<Eigen::VectorXd> centered{series.array() - series.mean()};
  Eigen::VectorXd c = PooledAutocovariance(centered, max_lag);
  if (IsZeroVariance(c(0), series.squaredNorm() / static_cast<double>(n))) {
    Eigen::VectorXd r = Eigen::VectorXd::Zero(max_lag + 1);
    r(0) = 1.0;
    return r;
  }
  return c / c(0);
}

Eigen::VectorXd SimulateRoughness(const ArParams& params, int n, std::uint64_t seed) {
  if (n <= 0) return Eigen::VectorXd();
  const int p = static_cast<int>(params.a.size());
  const int burn_in = 10 * p + 100;
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> innovation(0.0, 1.0);
  std::vector<double> x(static_cast<std::size_t>(burn_in) + n, 0.0);
  for (std::size_t t = 0; t < x.size(); ++t) {
    double v = params.sigma * innovation(rng);
    for (int j = 1; j <= p && static_cast<std::size_t>(j) <= t; ++j) v += params.a[j - 1] * x[t - j];
    x[t] = v;
  }
  return Eigen::Map<const Eigen::VectorXd>(x.data() + burn_in, n);
}

double ArProcessVariance(const std::vector<double>& a, double sigma) {
  double gain = 1.0;
  for (double k : ArToReflection(a)) {
    if (!(std::abs(k) < 1.0)) return std::numeric_limits<double>::infinity();
    gain *= 1.0 - k * k;
  }
  return sigma * sigma / gain;
}

std::vector<double> ArToReflection(const std::vector<double>& a) {
  const int p = static_cast<int>(a.size());
  std::vector<double> k(p, 0.0);
  std::vector<double> current = a;  // order m model, m = p down to 1
  for (int m = p; m >= 1; --m) {
    const double km = current[m - 1];
    k[m - 1] = km;
    const double denominator = 1.0 - km * km;
    if (m == 1) break;
    if (denominator == 0.0) break;  // lower orders undefined: left 0
    std::vector<double> lower(m - 1);
    for (int i = 1; i < m; ++i) lower[i - 1] = (current[i - 1] + km * current[m - i - 1]) / denominator;
    current = std::move(lower);
  }
  return k;
}

std::vector<double> ReflectionToAr(const std::vector<double>& k) {
  std::vector<double> a;
  for (std::size_t m = 1; m <= k.size(); ++m) {
    std::vector<double> next(m);
    for (std::size_t i = 1; i < m; ++i) next[i - 1] = a[i - 1] - k[m - 1] * a[m - i - 1];
    next[m - 1] = k[m - 1];
    a = std::move(next);
  }
  return a;
}

}  // namespace surfmap
