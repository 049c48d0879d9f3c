// Recompute and query cost of the map on finest levels of 10k-40k vertices
// (budget: recompute well under a second, a 100-point query far under 2 ms).
#include <random>

#include <benchmark/benchmark.h>
#include "server/map/friction_map.h"
#include "server/map/testing/flat_grid_levels.h"

namespace surfmap {
namespace {

std::vector<MapSample> SeededSamples(const SurfaceLevel& level, int count, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_int_distribution<int> pick(0, static_cast<int>(level.positions.size()) - 1);
  std::normal_distribution<double> noise(0.0, 0.01);
  std::vector<char> used(level.positions.size(), 0);
  std::vector<MapSample> samples;
  while (static_cast<int>(samples.size()) < count) {
    const int v = pick(rng);
    if (used[v]) continue;
    used[v] = 1;
    MapSample s;
    s.vertex = v;
    s.params.mu = (level.positions[v].x() < 50.0 ? 0.13 : 0.5) + noise(rng);
    s.params.mu_std = 0.01;
    s.params.reflection = {0.6, -0.3};
    s.params.sigma = 0.1;
    samples.push_back(s);
  }
  return samples;
}

// Arg: grid cells per side (100 -> 10,201 vertices, 200 -> 40,401).
void BM_MapRecompute(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  const SurfaceLevel level = testing::MakeFlatGrid(n, n, 100.0 / n);
  auto map = FrictionMap::Create(level);
  const auto samples = SeededSamples(level, 150, 1);
  for (auto _ : state) {
    auto status = map->SetSamples(samples);
    benchmark::DoNotOptimize(status);
  }
  state.counters["vertices"] = static_cast<double>(level.positions.size());
}
BENCHMARK(BM_MapRecompute)->Arg(100)->Arg(200)->Unit(benchmark::kMillisecond);

void BM_MapPendingUpdate(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  const SurfaceLevel level = testing::MakeFlatGrid(n, n, 100.0 / n);
  auto map = FrictionMap::Create(level);
  (void)map->SetSamples(SeededSamples(level, 150, 1));
  for (auto _ : state) {
    auto status = map->SetPendingVertices({1, 2, 3});
    benchmark::DoNotOptimize(status);
  }
}
BENCHMARK(BM_MapPendingUpdate)->Arg(200)->Unit(benchmark::kMillisecond);

void BM_MapQuery100Points(benchmark::State& state) {
  const SurfaceLevel level = testing::MakeFlatGrid(200, 200, 0.5);
  auto map = FrictionMap::Create(level);
  (void)map->SetSamples(SeededSamples(level, 150, 1));
  std::mt19937_64 rng(2);
  std::uniform_int_distribution<int> tri(0, static_cast<int>(level.triangles.size()) - 1);
  std::vector<SurfacePoint> points(100);
  for (auto& p : points) {
    p.triangle = tri(rng);
    p.barycentric = Eigen::Vector3d(0.2, 0.3, 0.5);
  }
  for (auto _ : state) {
    for (const auto& p : points) benchmark::DoNotOptimize(map->ValueAt(p));
  }
}
BENCHMARK(BM_MapQuery100Points)->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace surfmap

BENCHMARK_MAIN();
