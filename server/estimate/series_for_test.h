// Synthetic per-pair friction series for the estimation tests: stretches of
// the paper's textures about a material's mu, on the paper's pair spacing.
#pragma once

#include <cstdint>
#include <vector>

#include <Eigen/Core>
#include "server/estimate/roughness.h"

namespace surfmap::testing {

// Pair spacing of the paper's drag: 10 mm/s sampled at 100 Hz.
inline constexpr double kSpacingMm = 0.1;
// A 16 mm data window.
inline constexpr int kPairs = 160;

inline std::vector<double> Positions(int n) {
  std::vector<double> s(n);
  for (int i = 0; i < n; ++i) s[i] = 2.0 + kSpacingMm * i;
  return s;
}

struct Stretch {
  int length;
  double mean;
  ArParams texture;  // per-pair deviation about the mean
};

// The stretches one after another, each an independent realisation of its
// texture about its mean (a material change restarts the texture).
inline std::vector<double> Series(const std::vector<Stretch>& stretches, std::uint64_t seed) {
  std::vector<double> x;
  std::uint64_t k = 0;
  for (const Stretch& s : stretches) {
    const Eigen::VectorXd t = SimulateRoughness(s.texture, s.length, seed * 1000 + k++);
    for (int i = 0; i < s.length; ++i) x.push_back(s.mean + t(i));
  }
  return x;
}

// Per-pair friction textures of the paper's materials at 5 N (texture force
// / normal force): the AR(2) of docs/method.md with sigma divided by 5 N.
inline const ArParams kGlassLike{{0.0, 0.0}, 0.003};
inline const ArParams kRubberLike{{0.60, 0.25}, 0.11 / 5.0};
inline const ArParams kMasoniteLike{{1.61, -0.73}, 0.16 / 5.0};
inline const ArParams kSandpaperLike{{0.30, 0.10}, 0.25 / 5.0};

}  // namespace surfmap::testing
