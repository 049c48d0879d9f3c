#include "server/haptics/spatial_texture.h"

#include <cmath>
#include <random>

#include "server/base/splitmix64.h"

namespace surfmap::haptics {
namespace {

constexpr int kTableBits = 16;
constexpr std::uint64_t kTableMask = (1u << kTableBits) - 1;

}  // namespace

void ReflectionToArInPlace(const double* k, int order, double* a) {
  double prev[kMaxArOrder];
  for (int m = 0; m < order; ++m) {
    for (int i = 0; i < m; ++i) prev[i] = a[i];
    for (int i = 0; i < m; ++i) a[i] = prev[i] - k[m] * prev[m - 1 - i];
    a[m] = k[m];
  }
}

void UpdateImpulse(const double* a, int order, ArImpulse& impulse) {
  if (impulse.order == order) {
    bool same = true;
    for (int i = 0; i < order && same; ++i) same = impulse.a[i] == a[i];
    if (same) return;
  }
  impulse.order = order;
  for (int i = 0; i < order; ++i) impulse.a[i] = a[i];
  double energy = 0.0;
  int n = 0;
  for (; n < kMaxImpulseLength; ++n) {
    double h = n == 0 ? 1.0 : 0.0;
    for (int i = 1; i <= order && i <= n; ++i) h += a[i - 1] * impulse.h[n - i];
    impulse.h[n] = h;
    energy += h * h;
    // Stop once the last max(order, 1) values together carry less than
    // kTailEnergy / 100 of the energy so far: for a stationary model the rest
    // of the tail decays geometrically from there, and its sum is about
    // recent / (1 - |z|^2) for the largest root z, so the factor 100 covers
    // roots up to |z| ~ 0.995 (checking `order` consecutive values keeps an
    // oscillating response from stopping at a zero crossing).
    const int window = order > 0 ? order : 1;
    if (n + 1 >= window && n >= order) {
      double recent = 0.0;
      for (int i = 0; i < window; ++i) recent += impulse.h[n - i] * impulse.h[n - i];
      if (recent < kTailEnergy * energy * 1e-2) {
        ++n;
        break;
      }
    }
  }
  impulse.length = n;
  impulse.variance_gain = energy;
}

SpatialTexture::SpatialTexture(std::uint64_t seed) : seed_(seed), table_(kTableMask + 1) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  double sum = 0.0;
  for (double& v : table_) {
    v = normal(rng);
    sum += v;
  }
  // Exactly mean 0, variance 1 over the table: the finite table's own
  // sampling error would otherwise scale every texture's amplitude.
  const double mean = sum / static_cast<double>(table_.size());
  double ss = 0.0;
  for (double& v : table_) {
    v -= mean;
    ss += v * v;
  }
  const double scale = 1.0 / std::sqrt(ss / static_cast<double>(table_.size()));
  for (double& v : table_) v *= scale;
}

double SpatialTexture::Innovation(std::int64_t k) const {
  // SplitMix64's finaliser: every input bit affects every output bit, so
  // consecutive cells index unrelated table entries.
  return table_[SplitMix64Finalize(static_cast<std::uint64_t>(k) ^ SplitMix64Finalize(seed_)) & kTableMask];
}

double SpatialTexture::Roughness(std::int64_t k, double sigma, const ArImpulse& impulse) const {
  if (sigma <= 0.0) return 0.0;
  double r = 0.0;
  for (int j = 0; j < impulse.length; ++j) r += impulse.h[j] * Innovation(k - j);
  return sigma * r;
}

}  // namespace surfmap::haptics
