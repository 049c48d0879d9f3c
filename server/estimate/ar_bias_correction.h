// Small-sample bias of an AR fit, by parametric bootstrap.
//
// Burg and least squares are consistent but biased at finite length, and the
// mean / line removed from every segment before the fit adds to it: the bias
// is O(1/n) per segment and pulls the coefficients towards a white process.
// Measured on rubber (a1 0.60, a2 0.25), two detrended segments of n points,
// Burg, mean of 400 seeds (zz experiment, see docs/method.md section 5):
// n = 40: a2 0.140; 60: 0.181; 100: 0.213; 160: 0.228; 400: 0.241. A whole
// 20 mm drag (two passes of ~160 points) loses ~0.02, a third of its standard
// error; a 5 mm piece of a drag that crossed a change (two passes of ~45
// points) loses ~0.1, which the map's per-region medians then carry whole
// (medians of pieces do not average a bias away).
//
// The correction (Efron's bootstrap bias estimate, parametric form): simulate
// `replicates` sets of segments of the same lengths from the fitted model
// (plus white noise of the fit's noise variance), treat them exactly as the
// data were treated (line removed when the data's was, same method, same
// noise correction), fit each, and take bias = mean(replicate fits) - fit;
// the corrected coefficients are fit - bias, and sigma likewise (the same
// short detrended segments read it low: rubber, 2 x 50 points, mean of 200
// seeds, 0.105 for 0.11; ar_bias_correction_test). The estimate's Monte-Carlo error
// is the coefficients' spread / sqrt(replicates) (~0.012 for a 5 mm rubber
// piece at 64 replicates). If the corrected model is not stationary, the
// correction is halved until it is (or dropped).
#pragma once

#include <cstdint>
#include <vector>

#include <Eigen/Core>

namespace surfmap {

struct ArFitOptions;

struct ArBiasEstimate {
  std::vector<double> bias;   // mean replicate fit minus the model, per coefficient
  double sigma_bias = 0.0;    // mean replicate innovation std minus the model's sigma
  int replicates_used = 0;    // replicates whose fit succeeded
};

// The bias of the estimator `options` (its bias_replicates, segments_detrended
// and bias_seed) at the model (a, sigma) for segments of the given lengths.
// Replicate fits run without a bias correction of their own. Deterministic for
// a seed.
ArBiasEstimate EstimateArBias(const std::vector<double>& a, double sigma, const std::vector<int>& segment_lengths,
                              const ArFitOptions& options);

// The seed of one random stream of bias replicate `replicate`: stream 0 is
// the sensor noise, stream s + 1 the texture of segment s. SplitMix64 of the
// replicate's own SplitMix64-mixed seed, so no two (seed, replicate, stream)
// share a stream short of a 64-bit collision.
std::uint64_t BiasReplicateSeed(std::uint64_t bias_seed, int replicate, int stream);

// A bias seed from a piece's own numbers (its mu and start, mm): SplitMix64
// over their bit patterns, the same on every platform (std::hash<double> is
// implementation-defined).
std::uint64_t BiasSeedFromData(double mu, double start_mm);

// a - t * bias with t the largest of 1, 1/2, 1/4, 1/8, 0 that leaves the model
// stationary.
std::vector<double> ApplyArBiasCorrection(const std::vector<double>& a, const std::vector<double>& bias);

}  // namespace surfmap
