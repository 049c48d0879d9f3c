// Speed of the AR fit on drag-sized series. A typical drag gives ~240 grid
// points per pass at L = 0.1 mm (20 mm minus the trimmed transients).
#include <algorithm>
#include <vector>

#include <benchmark/benchmark.h>

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
BENCHMARK(BM_LagProductsPortable);
BENCHMARK(BM_LagProductsAvx2);

BENCHMARK(BM_BurgAr2)->Arg(240)->Arg(2400);
BENCHMARK(BM_BurgAr2NoiseAware)->Arg(240);
BENCHMARK(BM_LeastSquaresAr2)->Arg(240)->Arg(2400);
BENCHMARK(BM_BurgAr2TwoPasses);

}  // namespace
}  // namespace surfmap

BENCHMARK_MAIN();
