// Roughness as a stationary autoregressive process over arc length.
//
// The input is the force variation about the Coulomb nominal, already resampled
// on a uniform arc-length grid of step L (mm) and detrended (see fit_trace.h).
// Model: f(k) = a1 f(k-1) + ... + ap f(k-p) + sigma e(k), e ~ N(0, 1).
//
// Conventions used throughout:
// - Characteristic polynomial z^p - a1 z^(p-1) - ... - ap; the model is
//   stationary iff all its roots lie strictly inside the unit circle.
// - Reflection coefficients are PARCOR (partial autocorrelation) coefficients:
//   k_m is the last coefficient of the order-m model, so for AR(1) k1 = a1.
//   Step-up: a_m,i = a_{m-1},i - k_m a_{m-1},m-i, a_m,m = k_m.
#pragma once

#include <cstdint>
#include <initializer_list>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include "absl/status/statusor.h"

namespace surfmap {

enum class ArMethod {
  // Burg's lattice method: minimises forward + backward prediction error
  // stage by stage. Always returns a stationary model (|k| < 1); little bias
  // near the unit circle (periodic textures).
  kBurg,
  // Covariance method: ordinary least squares of f(k) on f(k-1..k-p) over the
  // rows that lie inside one segment. May return a non-stationary model; check
  // ArFit::stationary.
  kLeastSquares,
};

struct ArFitOptions {
  int order = 2;                    // p, 1..20
  ArMethod method = ArMethod::kBurg;
  double step_mm = 0.1;             // grid step L (> 0), used for lengths in mm
  // Variance of white measurement noise riding on the series (N^2), e.g. from
  // the pause; 0 = none. Used to de-bias the fit (noise-aware roughness):
  // - kBurg: noise-compensated Burg. At stage m the expected noise energy of the
  //   forward/backward prediction errors, 2 N_m noise_variance (1 + sum a_j^2),
  //   is removed from Burg's denominator and the expected noise cross term,
  //   N_m noise_variance sum a_j a_(m-j), from its numerator (a = the order m-1
  //   model, N_m = number of error pairs). The innovation variance starts from
  //   the de-noised lag-0 autocovariance.
  // - kLeastSquares: bias-compensated least squares, (R - noise_variance I) a = r
  //   with R, r the lagged-regressor moments; the innovation variance is the
  //   residual variance minus noise_variance (1 + sum a_j^2).
  // Both are the Yule-Walker "subtract the noise from lag 0" correction carried
  // into the respective estimator, and consistent when the noise is white.
  double noise_variance = 0.0;
  // The same for noise that is not white: its autocovariance at lags 0, 1, ...
  // (N^2; lags past the end are 0), e.g. sensor noise after it has passed
  // through the estimated normals and the resampling (series_noise.h). Each
  // estimator then removes the noise's expected share of every lagged moment
  // (Burg: of its prediction errors' energy and cross products; least
  // squares: of X^T X and X^T y), consistent for any stationary noise of that
  // autocovariance. When set, noise_variance must be 0 and lag 0 plays its
  // part everywhere (noise floor, process variance, bias replicates, which
  // add white noise of that variance).
  std::vector<double> noise_autocovariance;
  // The texture is below the noise floor (ArFit::below_noise_floor) when the
  // series' variance is at most this many times the noise's (lag 0), >= 1.
  // 1.5: a texture of at most half the noise's variance. FitTrace asks 3.0 of
  // the noise it propagates (series_noise.h): a texture of at most twice the
  // noise the series carries, where version 7's 1.5 times the white model
  // (twice that noise) drew the line, so glass and steel stay unresolved.
  double noise_floor_ratio = 1.5;
  // >= 0; 0 = min(n/4, 200). Clamped to the shortest segment's length - 1.
  int acf_max_lag = 0;
  // Small-sample bias correction by parametric bootstrap (ar_bias_correction.h):
  // 0 = off (the default: a whole drag's bias is a third of its standard
  // error); > 0 = that many replicates (FitOptions turns it on for the pieces
  // of a drag that crossed a change, whose short segments lose ~0.1 of a2).
  // Applied when the uncorrected fit is stationary and above the noise floor;
  // a_stderr stays the uncorrected fit's.
  int bias_replicates = 0;
  // The caller removed a least-squares line from every segment
  // (ForceVariationSeries does: FitPieceRoughness sets this); the replicates
  // are treated the same way. Off by default: detrending replicates of a
  // series that was not detrended adds the detrend's own bias to the estimate.
  bool segments_detrended = false;
  std::uint64_t bias_seed = 1;
  // False (with a reason in *why, if given) for order outside 1..20, step_mm
  // <= 0 or non-finite, negative or non-finite noise_variance, a
  // noise_autocovariance with a non-finite entry, a negative lag 0, a lag
  // larger than lag 0 in size, more than 64 lags, or given with
  // noise_variance > 0, noise_floor_ratio below 1 or not finite,
  // acf_max_lag < 0, bias_replicates outside 0..10000.
  // NoiseAutocovariance() is the noise as the estimators take it.
  bool IsValid(std::string* why) const;
  std::vector<double> NoiseAutocovariance() const;
};

struct ArFit {
  std::vector<double> a;            // a1..ap
  // Asymptotic standard errors of a1..ap. Burg: sqrt of the diagonal of
  // sigma^2 Gamma_p^-1 / n, Gamma_p the p x p autocovariance (Toeplitz) matrix
  // of the fitted model. Least squares: s^2 (X^T X)^-1 with s^2 = RSS / (rows - p)
  // (noise-aware: s^2 (X^T X - rows noise_variance I)^-1, s^2 the residual
  // variance, noise included). Neither includes the extra spread the noise
  // correction adds, so treat them as lower bounds when noise_variance > 0.
  // With several segments n counts every sample, i.e. the segments are taken
  // as independent stretches of the process; the forward and reverse pass of
  // one drag feel the same texture, so there the errors are optimistic by up
  // to sqrt(2).
  std::vector<double> a_stderr;
  double sigma = 0.0;               // innovation standard deviation, N
  // Process variance: the pooled lag-0 sample autocovariance of the
  // mean-removed series, minus noise_variance (the texture's own variance,
  // clamped at 0), N^2.
  double variance = 0.0;
  bool stationary = false;          // all roots of z^p - a1 z^(p-1) - ... - ap inside the unit circle
  // Reflection (PARCOR) coefficients k1..kp, |k| < 1 iff stationary
  // (see ArToReflection for non-stationary models).
  std::vector<double> reflection;
  // Sample autocorrelation of the measured series (noise included), lags
  // 0..acf_max_lag, pooled over segments.
  std::vector<double> acf;
  // Correlation length: the (interpolated) lag after which |ACF| stays below
  // 1/e, times step_mm. Interpolation is log-linear between the last lag at or
  // above 1/e and the next, so a pure exponential a^k gives exactly
  // -step/ln(a). Computed on the fitted model's ACF when the fit is stationary
  // (noise-free and without the sampling wiggles of the sample ACF at long
  // lags), else on the sample ACF; if the sample ACF never settles below 1/e
  // within acf_max_lag, acf_max_lag * step_mm (a lower bound).
  double acf_decay_mm = 0.0;
  // Dominant spatial wavelength 2 pi L / |arg z| of the largest-modulus root z
  // of the characteristic polynomial; none when that root is real (no
  // oscillation) or the model's power spectrum peaks at zero frequency.
  std::optional<double> dominant_wavelength_mm;
  // True when the texture variance is not above the given measurement noise
  // (the sensor cannot resolve it): series variance <= noise_floor_ratio
  // times the noise's variance,
  // or the noise correction broke down (de-noised moments not positive). The
  // fit is then returned without noise correction (or with the correction
  // clamped) and must be treated as an upper bound on the texture.
  bool below_noise_floor = false;
  int n = 0;                        // series length used (all segments)
};

// Fits AR(p) to `series` (mean removed inside). Same as the segments overload
// with one segment.
absl::StatusOr<ArFit> FitAutoregressive(const Eigen::VectorXd& series, const ArFitOptions& options);

// Fits one AR(p) process to several segments of it, e.g. the forward and the
// reverse pass of a drag. Each segment has its own mean removed; no lag or
// regression row ever spans a segment boundary (Burg sums its numerator and
// denominator over segments; least squares stacks rows per segment).
// Errors (INVALID_ARGUMENT, message names segment and sample): invalid options,
// no segments, a segment of <= order samples, fewer than 4 * (order + 1)
// samples in all or fewer lagged rows (sum of length - order) than one such
// series has (3 * order + 4), non-finite values, zero variance.
absl::StatusOr<ArFit> FitAutoregressive(const std::vector<Eigen::VectorXd>& segments,
                                        const ArFitOptions& options);
// Same, for a braced list: FitAutoregressive({forward, reverse}, options)
// (without this overload such a call would be ambiguous, as Eigen::VectorXd
// has a two-argument constructor).
absl::StatusOr<ArFit> FitAutoregressive(std::initializer_list<Eigen::VectorXd> segments,
                                        const ArFitOptions& options);

// Sample autocorrelation r(0..max_lag) of a (mean-removed inside) series,
// biased estimator (divides by n, so the sequence is positive definite).
// max_lag is clamped to [0, n-1]; an empty series gives an empty vector; a
// constant series gives r = (1, 0, 0, ...).
Eigen::VectorXd Autocorrelation(const Eigen::VectorXd& series, int max_lag);

struct ArParams {
  std::vector<double> a;  // a1..ap
  double sigma = 0.0;
};

// Resynthesises n samples of the AR process from seeded Gaussian innovations
// (std::mt19937_64(seed), std::normal_distribution; a burn-in of 10 * p + 100
// samples is discarded so the output is stationary). n <= 0 gives an empty
// vector. A non-stationary model is simulated as given (it will grow).
Eigen::VectorXd SimulateRoughness(const ArParams& params, int n, std::uint64_t seed);

// Reflection coefficients <-> AR coefficients (Levinson step-down / step-up).
// Maps interpolate in reflection coefficients: any |k| < 1 gives a stable model.
// ArToReflection of a non-stationary model yields some |k| >= 1; if a step
// meets |k| == 1 exactly the lower-order coefficients are undefined and
// returned as 0.
std::vector<double> ArToReflection(const std::vector<double>& a);
std::vector<double> ReflectionToAr(const std::vector<double>& k);

// The variance of the stationary AR process a driven by innovations of
// standard deviation sigma: sigma^2 / prod(1 - k_i^2), k = ArToReflection(a).
// Infinity for a non-stationary model.
double ArProcessVariance(const std::vector<double>& a, double sigma);

}  // namespace surfmap
