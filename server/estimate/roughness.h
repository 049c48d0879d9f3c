// Roughness as a stationary autoregressive process over arc length.
//
// The input is the force variation about the Coulomb nominal, already resampled
// on a uniform arc-length grid of step L (mm) and detrended (see fit_trace.h).
// Model: f(k) = a1 f(k-1) + ... + ap f(k-p) + sigma e(k), e ~ N(0, 1).
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include <Eigen/Core>
#include "absl/status/statusor.h"

namespace surfmap {

enum class ArMethod { kBurg, kLeastSquares };

struct ArFitOptions {
  int order = 2;                    // p >= 1
  ArMethod method = ArMethod::kBurg;
  double step_mm = 0.1;             // grid step L, used for lengths in mm
  // Variance of white measurement noise riding on the series (N^2), e.g. from
  // the pause; 0 = none. Used to de-bias the fit (noise-aware roughness).
  double noise_variance = 0.0;
  int acf_max_lag = 0;              // 0 = min(n/4, 200)
  bool IsValid(std::string* why) const;
};

struct ArFit {
  std::vector<double> a;            // a1..ap
  std::vector<double> a_stderr;     // asymptotic standard errors of a1..ap
  double sigma = 0.0;               // innovation standard deviation, N
  double variance = 0.0;            // process variance (lag-0 autocovariance), N^2
  bool stationary = false;          // all roots of z^p - a1 z^(p-1) - ... - ap inside the unit circle
  std::vector<double> reflection;   // reflection (PARCOR) coefficients k1..kp, |k| < 1 iff stationary
  std::vector<double> acf;          // sample autocorrelation, lags 0..acf_max_lag
  double acf_decay_mm = 0.0;        // first lag where the ACF envelope falls below 1/e, in mm
  std::optional<double> dominant_wavelength_mm;  // from complex AR roots; none when no oscillation
  // True when the texture variance is not above the given measurement noise
  // (the sensor cannot resolve it).
  bool below_noise_floor = false;
  int n = 0;                        // series length used
};

// Fits AR(p) to `series`. Errors: series shorter than 4 * (order + 1),
// non-finite values, zero variance, invalid options.
absl::StatusOr<ArFit> FitAutoregressive(const Eigen::VectorXd& series, const ArFitOptions& options);

// Sample autocorrelation r(0..max_lag) of a (mean-removed inside) series.
Eigen::VectorXd Autocorrelation(const Eigen::VectorXd& series, int max_lag);

struct ArParams {
  std::vector<double> a;  // a1..ap
  double sigma = 0.0;
};

// Resynthesises n samples of the AR process from seeded Gaussian innovations
// (a burn-in of 10 * p + 100 samples is discarded so the output is stationary).
Eigen::VectorXd SimulateRoughness(const ArParams& params, int n, std::uint64_t seed);

// Reflection coefficients <-> AR coefficients (Levinson step-up / step-down).
// Maps interpolate in reflection coefficients: any |k| < 1 gives a stable model.
std::vector<double> ArToReflection(const std::vector<double>& a);
std::vector<double> ReflectionToAr(const std::vector<double>& k);

}  // namespace surfmap
