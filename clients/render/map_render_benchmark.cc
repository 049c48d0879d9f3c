// Speed of the map renderer on a dense mesh (a level-3-like bottle has ~23k
// triangles): two 480 x 480 views + colour bar, and PNG encoding.
#include <cmath>
#include <numbers>

#include <benchmark/benchmark.h>
#include "clients/render/map_ply.h"
#include "clients/render/map_render.h"

namespace surfmap {
namespace {

// A UV sphere with about 2 * stacks * slices triangles and a step in value.
MapMesh DenseSphere(int stacks, int slices) {
  MapMesh m;
  for (int i = 0; i <= stacks; ++i) {
    const double phi = -std::numbers::pi / 2 + std::numbers::pi * i / stacks;
    for (int j = 0; j < slices; ++j) {
      const double th = 2 * std::numbers::pi * j / slices;
      const Eigen::Vector3d p(40 * std::cos(phi) * std::cos(th), 40 * std::cos(phi) * std::sin(th),
                              40 * std::sin(phi));
      m.positions.push_back(p);
      m.normals.push_back(p.normalized());
      m.values.push_back(p.x() > 10 && std::abs(p.z()) < 15 ? 0.5 : 0.13);
    }
  }
  for (int i = 0; i < stacks; ++i) {
    for (int j = 0; j < slices; ++j) {
      const int a = i * slices + j, b = i * slices + (j + 1) % slices;
      m.triangles.push_back({a, b, b + slices});
      m.triangles.push_back({a, b + slices, a + slices});
    }
  }
  return m;
}

void BM_RenderMapPng(benchmark::State& state) {
  const MapMesh mesh = DenseSphere(96, 120);  // 23k triangles
  MapOverlay overlay;
  for (int i = 0; i < 150; ++i) overlay.sample_points.push_back(mesh.positions[(i * 7919) % mesh.positions.size()]);
  const MapRenderOptions options;
  for (auto _ : state) {
    auto png = RenderMapPng(mesh, overlay, options);
    benchmark::DoNotOptimize(png);
  }
  state.counters["triangles"] = static_cast<double>(mesh.triangles.size());
}
BENCHMARK(BM_RenderMapPng)->Unit(benchmark::kMillisecond);

void BM_WriteMapPly(benchmark::State& state) {
  const MapMesh mesh = DenseSphere(96, 120);
  for (auto _ : state) {
    auto ply = WriteMapPly(mesh);
    benchmark::DoNotOptimize(ply);
  }
}
BENCHMARK(BM_WriteMapPly)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace surfmap

BENCHMARK_MAIN();
