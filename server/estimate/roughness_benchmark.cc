// Speed of the AR fit on drag-sized series. A typical drag gives ~240 grid
// points per pass at L = 0.1 mm (20 mm minus the trimmed transients).
#include <algorithm>
#include <vector>

#include <benchmark/benchmark.h>

#include "server/estimate/change_points.h"
#include "server/estimate/lag_products.h"
#include "server/estimate/roughness.h"

namespace surfmap {
namespace {

const ArParams kMasonite{{1.61, -0.73}, 0.16};

void FitBenchmark(benchmark::State& state, ArMethod method, double noise_variance) {
  const Eigen::VectorXd x = SimulateRoughness(kMasonite, static_cast<int>(state.range(0)), 1);
  ArFitOptions options;
  options.method = method;
  options.noise_variance = noise_variance;
  for (auto _ : state) {
    auto fit = FitAutoregressive(x, options);
    benchmark::DoNotOptimize(fit);
  }
  state.SetItemsProcessed(state.iterations());
}

void BM_BurgAr2(benchmark::State& state) { FitBenchmark(state, ArMethod::kBurg, 0.0); }
void BM_BurgAr2NoiseAware(benchmark::State& state) { FitBenchmark(state, ArMethod::kBurg, 0.01); }
void BM_LeastSquaresAr2(benchmark::State& state) { FitBenchmark(state, ArMethod::kLeastSquares, 0.0); }

void BM_BurgAr2TwoPasses(benchmark::State& state) {
  const std::vector<Eigen::VectorXd> passes{SimulateRoughness(kMasonite, 240, 1),
                                            SimulateRoughness(kMasonite, 240, 2)};
  ArFitOptions options;
  for (auto _ : state) {
    auto fit = FitAutoregressive(passes, options);
    benchmark::DoNotOptimize(fit);
  }
  state.SetItemsProcessed(state.iterations());
}

// The ACF's lagged products for one pass of a 45 mm drag (350 grid points,
// 176 lags): the portable Eigen GEMV path is the baseline for the AVX2 one.
void LagProductsBenchmark(benchmark::State& state, void (*kernel)(const double*, int, int, double*)) {
  const Eigen::VectorXd x = SimulateRoughness(kMasonite, 350, 1);
  std::vector<double> c(176);
  for (auto _ : state) {
    std::fill(c.begin(), c.end(), 0.0);
    kernel(x.data(), 350, 176, c.data());
    benchmark::DoNotOptimize(c.data());
  }
  state.SetItemsProcessed(state.iterations());
}
void BM_LagProductsPortable(benchmark::State& state) { LagProductsBenchmark(state, &AddLagProductsPortable); }
void BM_LagProductsAvx2(benchmark::State& state) {
  if (!CpuHasAvx2Fma()) {
    state.SkipWithError("no AVX2/FMA on this CPU");
    return;
  }
  LagProductsBenchmark(state, &AddLagProductsAvx2);
}
// Change points of a 16 mm data window (160 pairs, 0.1 mm apart): one
// material (segmentation only: its ends are tested and kept), and 0.9 mm of
// glass, rubber, masonite, glass (the end split off, the rest searched again).
// Per-pair mu at 5 N: texture sigma / 5.
void ChangePointsBenchmark(benchmark::State& state, bool with_end) {
  std::vector<double> s(160), x;
  for (int i = 0; i < 160; ++i) s[i] = 2.0 + 0.1 * i;
  auto add = [&x](int n, double mu, const ArParams& texture, int seed) {
    const Eigen::VectorXd t = SimulateRoughness(texture, n, seed);
    for (int i = 0; i < n; ++i) x.push_back(mu + t(i));
  };
  const ArParams glass{{0.0, 0.0}, 0.003}, rubber{{0.60, 0.25}, 0.022}, masonite{{1.61, -0.73}, 0.032};
  if (with_end) {
    add(9, 0.106, glass, 1), add(60, 0.305, rubber, 2), add(65, 0.36, masonite, 3), add(26, 0.106, glass, 4);
  } else {
    add(160, 0.305, rubber, 2);
  }
  for (auto _ : state) {
    auto changes = DetectChangePoints(s, x);
    benchmark::DoNotOptimize(changes);
  }
  state.SetItemsProcessed(state.iterations());
}
// One material over state.range(0) pairs at 0.1 mm: the band test's scan is
// bounded in width (change_points.cc, kMaxBandPairs), so the time grows
// about linearly with the drag's length, not with its square.
void BM_ChangePointsLongDrag(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  std::vector<double> s(n), x(n);
  const Eigen::VectorXd t = SimulateRoughness(ArParams{{0.60, 0.25}, 0.022}, n, 7);
  for (int i = 0; i < n; ++i) s[i] = 0.1 * i, x[i] = 0.305 + t(i);
  for (auto _ : state) {
    auto changes = DetectChangePoints(s, x);
    benchmark::DoNotOptimize(changes);
  }
  state.SetItemsProcessed(state.iterations() * n);  // items = pairs
}
void BM_ChangePointsOneMaterial(benchmark::State& state) { ChangePointsBenchmark(state, false); }
void BM_ChangePointsEndAndBands(benchmark::State& state) { ChangePointsBenchmark(state, true); }

BENCHMARK(BM_ChangePointsOneMaterial);
BENCHMARK(BM_ChangePointsEndAndBands);
BENCHMARK(BM_ChangePointsLongDrag)->Arg(1600)->Arg(16000)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_LagProductsPortable);
BENCHMARK(BM_LagProductsAvx2);

BENCHMARK(BM_BurgAr2)->Arg(240)->Arg(2400);
BENCHMARK(BM_BurgAr2NoiseAware)->Arg(240);
BENCHMARK(BM_LeastSquaresAr2)->Arg(240)->Arg(2400);
BENCHMARK(BM_BurgAr2TwoPasses);

}  // namespace
}  // namespace surfmap

BENCHMARK_MAIN();
