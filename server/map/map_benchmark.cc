// Recompute and query cost of the map on finest levels of 10k-40k vertices
// (budget: recompute well under a second, a 100-point query far under 2 ms),
// and what grouping regions into materials and splitting pieces against
// their textures add to a region map's rebuild.
#include <algorithm>
#include <cmath>
#include <random>
#include <string>

#include <benchmark/benchmark.h>
#include "server/estimate/series_for_test.h"
#include "server/map/friction_map.h"
#include "server/map/region_map.h"
#include "server/map/testing/flat_grid_levels.h"
#include "server/map/testing/map_pieces.h"

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

// 200 drags of 16 mm across S stripes of 4 textures in turn (each texture in
// S / 4 places, each stripe a region or more): the region map's whole
// rebuild (merging, materials, the random walker over 10,201 vertices).
// Args: pool_alike_regions off (0) / on (1), S (10: 10 mm stripes; 50: 2 mm,
// ~50 regions, every pair a candidate for a material); the ratio of on to
// off is what materials cost.
void BM_RegionMapRebuild(benchmark::State& state) {
  const SurfaceLevel level = testing::MakeFlatGrid(100, 100, 1.0);
  RegionMapOptions options;
  options.pool_alike_regions = state.range(0) != 0;
  auto map = RegionMap::Create(level, options);
  const double mu[4] = {0.106, 0.305, 0.36, 0.5};
  const std::vector<double> k[4] = {{0.0, 0.0}, {0.8, 0.25}, {0.93, -0.73}, {0.33, 0.1}};
  std::mt19937_64 rng(3);
  const int stripes = static_cast<int>(state.range(1));
  const double width = 100.0 / stripes;
  std::uniform_real_distribution<double> across(0.15 * width, 0.85 * width), along(2.0, 82.0);
  std::normal_distribution<double> noise(0.0, 1.0);
  std::vector<MapPiece> pieces;
  for (int d = 0; d < 200; ++d) {
    const int stripe = d % stripes, texture = stripe % 4;
    const double x = width * stripe + across(rng), y = along(rng);
    MapPiece p = testing::StraightPiece(d, {x, y, 0}, {x, y + 16, 0}, mu[texture] + 0.01 * noise(rng), 0.0,
                                        texture > 0, 0.01);
    if (texture > 0) {
      p.piece.texture.reflection.clear();
      for (double kj : k[texture]) p.piece.texture.reflection.push_back(std::clamp(kj + 0.05 * noise(rng), -0.98, 0.98));
      p.piece.roughness_rows = 150;
    }
    pieces.push_back(std::move(p));
  }
  if (!map.ok()) return state.SkipWithError(std::string(map.status().message()).c_str());
  for (auto _ : state) {
    // Placement is cached for identical pieces; the rebuild is what repeats.
    if (absl::Status status = map->SetPieces(pieces); !status.ok()) {
      return state.SkipWithError(std::string(status.message()).c_str());
    }
  }
  int materials = 0;
  for (const TextureRegion& r : map->regions()) materials = std::max(materials, r.material + 1);
  state.counters["regions"] = static_cast<double>(map->regions().size());
  state.counters["materials"] = materials;
}
BENCHMARK(BM_RegionMapRebuild)->ArgsProduct({{0, 1}, {10, 50}})->Unit(benchmark::kMillisecond);

// What testing pieces again against the materials' textures costs
// (RegionMapOptions::split_against_materials, piece_resplit.h): 200 drags of
// 16 mm with their pair series (160 pairs each) on 10 mm stripes of rubber
// and masonite in turn, every fourth drag across a boundary between them as
// one piece (no change detected). Arg: the plan's own map (0: no split, no
// texture assignment, no chains carried on: PlanRegionMapOptions in
// server/plan) / the served map's defaults (1) / the split alone (2) / the
// served map's defaults linking regions instead of materials (3) / the
// served map's defaults without the misfit-piece test, neither leaving
// misfits out of the mu nor moving them (4) / the served map's defaults
// without dissolving mixture materials (5) / the served map's defaults
// without bridges (6, boundary_bridges.h); with
// the split the pieces are grouped twice (once to find the materials, once
// with the parts) and spread once.
void BM_RegionMapSplitAgainstMaterials(benchmark::State& state) {
  const SurfaceLevel level = testing::MakeFlatGrid(100, 100, 1.0);
  RegionMapOptions options;
  if (state.range(0) == 0 || state.range(0) == 2) {
    options.split_against_materials = state.range(0) == 2;
    options.assign_by_texture = false;
    options.dissolve_mixture_materials = false;
    options.links.max_extension_turn_deg = 0.0;
    options.links.max_bridge_mm = 0.0;
    options.link_materials = false;
  }
  if (state.range(0) == 3) options.link_materials = false;
  if (state.range(0) == 4) options.exclude_misfit_pieces_from_mu = options.move_misfit_pieces = false;
  if (state.range(0) == 5) options.dissolve_mixture_materials = false;
  if (state.range(0) == 6) options.links.max_bridge_mm = 0.0;
  auto map = RegionMap::Create(level, options);
  if (!map.ok()) return state.SkipWithError(std::string(map.status().message()).c_str());
  const testing::Stretch rubber{0, 0.305, testing::kRubberLike}, masonite{0, 0.36, testing::kMasoniteLike};
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> along(2.0, 82.0), inside(2.0, 8.0), split(4.0, 12.0);
  std::vector<MapPiece> pieces;
  for (int d = 0; d < 200; ++d) {
    const int stripe = d % 10;
    testing::Stretch first = stripe % 2 == 0 ? rubber : masonite, second = stripe % 2 == 0 ? masonite : rubber;
    const double y = along(rng);
    Eigen::Vector3d a, b;
    std::vector<testing::Stretch> stretches;
    if (d % 4 == 3 && stripe < 9) {  // across the boundary at x = 10 (stripe + 1)
      const double before = split(rng);
      a = {10.0 * (stripe + 1) - before, y, 0};
      b = a + Eigen::Vector3d(15.9, 0, 0);
      first.length = static_cast<int>(10 * before);
      second.length = 160 - first.length;
      stretches = {first, second};
    } else {
      const double x = 10.0 * stripe + inside(rng);
      a = {x, y, 0};
      b = {x, y + 15.9, 0};
      first.length = 160;
      stretches = {first};
    }
    const std::vector<double> x = testing::Series(stretches, 1000 + d);
    double mean = 0.0, var = 0.0;
    for (double v : x) mean += v / x.size();
    for (double v : x) var += (v - mean) * (v - mean) / (x.size() - 1);
    MapPiece p = testing::StraightPiece(d, a, b, mean, 0.0, false, std::sqrt(var / 10.0));
    p.piece.texture.mu_std = std::sqrt(var);
    p.point_s_mm = {0.0, p.piece.end_mm};
    for (std::size_t i = 0; i < x.size(); ++i) p.pair_s_mm.push_back(0.1 * i);
    p.pair_mu = x;
    pieces.push_back(std::move(p));
  }
  for (auto _ : state) {
    if (absl::Status status = map->SetPieces(pieces); !status.ok()) {
      return state.SkipWithError(std::string(status.message()).c_str());
    }
  }
  state.counters["split"] = map->split_pieces();
  state.counters["regions"] = static_cast<double>(map->regions().size());
  state.counters["links"] = map->boundary_links();
  state.counters["bridges"] = map->boundary_bridges();
}
BENCHMARK(BM_RegionMapSplitAgainstMaterials)->DenseRange(0, 6)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace surfmap

BENCHMARK_MAIN();
