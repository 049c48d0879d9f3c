// How often the change test fires, measured with DetectChangePoints itself
// on seeded AR(2) series (figures, not speed: each benchmark runs once and
// reports its rate as a counter).
//
//   build/server/estimate/change_points_rates_benchmark
//
// false_alarms: one material over a 16 mm window (160 pairs at 0.1 mm), the
// share of series in which any change is reported. At the default 1e-3 it
// says whether the Bonferroni critical value has room to come down (it has
// none where the measured rate is already at or above 1e-3).
// detected: rubber then masonite, 48 pairs each (a 12 mm drag split at its
// middle), the share in which a change is found within 1 mm of the true one.
// strip_detected: a 7 mm rubber strip crossed inside masonite (45 | 70 | 45
// pairs), the share in which both its edges are found within 1.5 mm (no
// single split separates it: the band test of change_points.h).
// Textures: the paper's materials at 5 N, as in change_points_test.cc.
#include <cmath>
#include <cstdint>
#include <vector>

#include <benchmark/benchmark.h>

#include "server/estimate/change_points.h"
#include "server/estimate/roughness.h"

namespace surfmap {
namespace {

constexpr double kSpacingMm = 0.1;
const ArParams kWhite{{0.0, 0.0}, 0.02};
const ArParams kRubberLike{{0.60, 0.25}, 0.11 / 5.0};
const ArParams kMasoniteLike{{1.61, -0.73}, 0.16 / 5.0};
const ArParams kSandpaperLike{{0.30, 0.10}, 0.25 / 5.0};

std::vector<double> Positions(int n) {
  std::vector<double> s(n);
  for (int i = 0; i < n; ++i) s[i] = kSpacingMm * i;
  return s;
}

// `first` pairs of texture a about mean_a, then `second` of b about mean_b,
// each an independent realisation (a material change restarts the texture).
std::vector<double> Series(const ArParams& a, double mean_a, int first, const ArParams& b, double mean_b, int second,
                           std::uint64_t seed) {
  std::vector<double> x;
  const Eigen::VectorXd ta = SimulateRoughness(a, first, 2 * seed);
  for (int i = 0; i < first; ++i) x.push_back(mean_a + ta(i));
  if (second > 0) {
    const Eigen::VectorXd tb = SimulateRoughness(b, second, 2 * seed + 1);
    for (int i = 0; i < second; ++i) x.push_back(mean_b + tb(i));
  }
  return x;
}

ChangePointOptions WithFalseAlarm(double probability) {
  ChangePointOptions o;
  o.false_alarm_probability = probability;
  return o;
}

void BM_FalseAlarms(benchmark::State& state, const ArParams& texture, double probability) {
  constexpr int kPairs = 160;
  const int series = static_cast<int>(state.range(0));
  const std::vector<double> s = Positions(kPairs);
  int alarms = 0;
  for (auto _ : state) {
    for (int seed = 1; seed <= series; ++seed) {
      auto changes = DetectChangePoints(s, Series(texture, 0.3, kPairs, texture, 0.0, 0, seed), WithFalseAlarm(probability));
      if (!changes.ok()) {
        state.SkipWithError(changes.status().ToString().c_str());
        return;
      }
      alarms += !changes->empty();
    }
  }
  state.counters["false_alarms"] = static_cast<double>(alarms) / series;
  state.counters["series"] = series;
}

void BM_RubberThenMasoniteDetected(benchmark::State& state, double probability) {
  constexpr int kSide = 48;
  const int series = static_cast<int>(state.range(0));
  const std::vector<double> s = Positions(2 * kSide);
  const double truth_mm = 0.5 * (s[kSide - 1] + s[kSide]);
  int found = 0;
  for (auto _ : state) {
    for (int seed = 1; seed <= series; ++seed) {
      auto changes = DetectChangePoints(s, Series(kRubberLike, 0.305, kSide, kMasoniteLike, 0.36, kSide, seed),
                                        WithFalseAlarm(probability));
      if (!changes.ok()) {
        state.SkipWithError(changes.status().ToString().c_str());
        return;
      }
      bool hit = false;
      for (const ChangePoint& c : *changes) hit |= std::abs(c.s_mm - truth_mm) <= 1.0;
      found += hit;
    }
  }
  state.counters["detected"] = static_cast<double>(found) / series;
  state.counters["series"] = series;
}

void BM_RubberStripInMasoniteDetected(benchmark::State& state, double probability) {
  constexpr int kSide = 45, kStrip = 70;
  const int series = static_cast<int>(state.range(0));
  const std::vector<double> s = Positions(2 * kSide + kStrip);
  const double left_mm = 0.5 * (s[kSide - 1] + s[kSide]);
  const double right_mm = 0.5 * (s[kSide + kStrip - 1] + s[kSide + kStrip]);
  int found = 0;
  for (auto _ : state) {
    for (int seed = 1; seed <= series; ++seed) {
      std::vector<double> x = Series(kMasoniteLike, 0.36, kSide, kRubberLike, 0.305, kStrip, seed);
      const std::vector<double> rest = Series(kMasoniteLike, 0.36, kSide, kMasoniteLike, 0.0, 0, seed + 1000003);
      x.insert(x.end(), rest.begin(), rest.end());
      auto changes = DetectChangePoints(s, x, WithFalseAlarm(probability));
      if (!changes.ok()) {
        state.SkipWithError(changes.status().ToString().c_str());
        return;
      }
      bool left = false, right = false;
      for (const ChangePoint& c : *changes) {
        left |= std::abs(c.s_mm - left_mm) <= 1.5;
        right |= std::abs(c.s_mm - right_mm) <= 1.5;
      }
      found += left && right;
    }
  }
  state.counters["strip_detected"] = static_cast<double>(found) / series;
  state.counters["series"] = series;
}

// 20,000 one-material series resolve a 1e-3 rate to about +-22 %
// (sqrt(20) / 20); 2,000 crossings resolve a detection share to +-1 point.
BENCHMARK_CAPTURE(BM_FalseAlarms, white_1e3, kWhite, 1e-3)->Arg(20000)->Iterations(1)->Unit(benchmark::kSecond);
BENCHMARK_CAPTURE(BM_FalseAlarms, rubber_1e3, kRubberLike, 1e-3)->Arg(20000)->Iterations(1)->Unit(benchmark::kSecond);
BENCHMARK_CAPTURE(BM_FalseAlarms, masonite_1e3, kMasoniteLike, 1e-3)
    ->Arg(20000)
    ->Iterations(1)
    ->Unit(benchmark::kSecond);
BENCHMARK_CAPTURE(BM_FalseAlarms, sandpaper_1e3, kSandpaperLike, 1e-3)
    ->Arg(20000)
    ->Iterations(1)
    ->Unit(benchmark::kSecond);
BENCHMARK_CAPTURE(BM_FalseAlarms, masonite_1e2, kMasoniteLike, 1e-2)
    ->Arg(20000)
    ->Iterations(1)
    ->Unit(benchmark::kSecond);
BENCHMARK_CAPTURE(BM_RubberThenMasoniteDetected, at_1e3, 1e-3)->Arg(2000)->Iterations(1)->Unit(benchmark::kSecond);
BENCHMARK_CAPTURE(BM_RubberThenMasoniteDetected, at_1e2, 1e-2)->Arg(2000)->Iterations(1)->Unit(benchmark::kSecond);
BENCHMARK_CAPTURE(BM_RubberStripInMasoniteDetected, at_1e3, 1e-3)->Arg(2000)->Iterations(1)->Unit(benchmark::kSecond);

}  // namespace
}  // namespace surfmap

BENCHMARK_MAIN();
