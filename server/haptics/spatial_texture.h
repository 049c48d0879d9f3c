// SpatialTexture: the AR roughness resynthesised as a function of PLACE, not
// of time. The roughness force at arc-length cell k (k = round(s / step)) is
//
//   r(k) = sigma * sum_{j=0}^{J-1} h_j e(k - j)
//
// with h the impulse response of the AR model (h_0 = 1, h_j = sum_i a_i h_(j-i))
// truncated where its tail has no energy left, and e(k) a seeded standard
// normal looked up by hashing the cell index: e depends only on (seed, k).
// So r is a pure function of the cell: a probe that stops feels a constant
// force, and one that goes back over the same cells feels exactly the same
// texture in reverse, which a time-driven AR filter cannot do. For fixed
// parameters r is a stationary process with the AR model's autocovariance
// (up to the truncation, whose left-over variance is below kTailEnergy).
// Where the parameters change along the path (a region boundary), the filter
// changes with them: a moving-average with varying weights, continuous in
// the parameters.
//
// No allocation after construction: the impulse response lives in a
// fixed-size ArImpulse the caller owns (one per probe, reused while the
// parameters stay the same).
#pragma once

#include <array>
#include <cstdint>
#include <vector>

namespace surfmap::haptics {

inline constexpr int kMaxArOrder = 20;
inline constexpr int kMaxImpulseLength = 512;
// The truncation drops at most this share of the process variance.
inline constexpr double kTailEnergy = 1e-6;

// A model's impulse response, cached per probe.
struct ArImpulse {
  std::array<double, kMaxArOrder> a{};     // the model it was computed for
  int order = -1;                          // -1: not computed yet
  std::array<double, kMaxImpulseLength> h{};
  int length = 0;
  double variance_gain = 0.0;              // sum h_j^2: Var r = sigma^2 * variance_gain
};

// Recomputes `impulse` for AR coefficients a[0..order) unless it already
// holds them. A non-stationary model is cut at kMaxImpulseLength.
void UpdateImpulse(const double* a, int order, ArImpulse& impulse);

// Levinson step-up from reflection coefficients k[0..order) to AR
// coefficients a[0..order) without allocation (roughness.h's ReflectionToAr
// returns a vector).
void ReflectionToArInPlace(const double* k, int order, double* a);

class SpatialTexture {
 public:
  // `seed` picks the realisation; the noise table has 2^16 seeded normals
  // (mean 0, variance 1 exactly after normalisation).
  explicit SpatialTexture(std::uint64_t seed = 1);

  // The unit-variance innovation of cell k.
  double Innovation(std::int64_t k) const;

  // r(k) for a model of innovation std `sigma` with the given impulse.
  double Roughness(std::int64_t k, double sigma, const ArImpulse& impulse) const;

  std::uint64_t seed() const { return seed_; }

 private:
  std::uint64_t seed_;
  std::vector<double> table_;
};

}  // namespace surfmap::haptics
