// Loop refinement and surface queries at service sizes. Requirement: a
// 10k-face control mesh refined to level 3 in < 0.5 s (Create, including the
// closest-point tree); 100 closest-point queries well under 2 ms.
#include <malloc.h>

#include <random>
#include <vector>

#include <benchmark/benchmark.h>
#include "server/mesh/loop_surface.h"
#include "server/mesh/primitive_meshes.h"

namespace surfmap {
namespace {

// 2 * 100 * (49 + 1) = 10,000 faces: a closed cylinder, r 40 mm, h 200 mm.
const ControlMesh& TenThousandFaces() {
  static const ControlMesh mesh = *MakeCylinder(40.0, 200.0, 100, 49);
  return mesh;
}

const LoopSurface& TenThousandFacesLevel3() {
  static const std::unique_ptr<LoopSurface> surface = std::move(*LoopSurface::Create(TenThousandFaces(), 3));
  return *surface;
}

void BM_CreateLevel3TenThousandFaces(benchmark::State& state) {
  const ControlMesh& mesh = TenThousandFaces();
  std::size_t finest_vertices = 0;
  for (auto _ : state) {
    absl::StatusOr<std::unique_ptr<LoopSurface>> surface = LoopSurface::Create(mesh, static_cast<int>(state.range(0)));
    if (!surface.ok()) {
      state.SkipWithError(std::string(surface.status().message()).c_str());
      return;
    }
    finest_vertices = (*surface)->finest().positions.size();
    benchmark::DoNotOptimize(surface);
  }
  state.counters["control_faces"] = static_cast<double>(mesh.triangles.size());
  state.counters["finest_vertices"] = static_cast<double>(finest_vertices);
}
BENCHMARK(BM_CreateLevel3TenThousandFaces)->Arg(1)->Arg(2)->Arg(3)->Unit(benchmark::kMillisecond);

// The same with glibc told to keep freed memory (no trimming, no mmap for
// big blocks), so every iteration after the first reuses warm pages: this
// separates the computation from first-touch page faults, which cost ~7 ms per
// MB on the project's VMs (vs ~0.2 ms per MB on bare metal). A long-running
// server that has refined one mesh is in this state for the next.
void BM_CreateLevel3TenThousandFacesWarmHeap(benchmark::State& state) {
  mallopt(M_MMAP_THRESHOLD, 1 << 30);
  mallopt(M_TRIM_THRESHOLD, 1 << 30);
  const ControlMesh& mesh = TenThousandFaces();
  benchmark::DoNotOptimize(LoopSurface::Create(mesh, 3));  // warm the heap
  for (auto _ : state) {
    absl::StatusOr<std::unique_ptr<LoopSurface>> surface = LoopSurface::Create(mesh, 3);
    benchmark::DoNotOptimize(surface);
  }
}
BENCHMARK(BM_CreateLevel3TenThousandFacesWarmHeap)->Unit(benchmark::kMillisecond)->MinTime(2.0);

// Baseline: copying the finest level's vertex positions once (what any
// per-vertex pass over level 3 costs at minimum).
void BM_CopyLevel3Positions(benchmark::State& state) {
  const std::vector<Eigen::Vector3d>& positions = TenThousandFacesLevel3().finest().positions;
  for (auto _ : state) {
    std::vector<Eigen::Vector3d> copy = positions;
    benchmark::DoNotOptimize(copy.data());
  }
  state.counters["finest_vertices"] = static_cast<double>(positions.size());
}
BENCHMARK(BM_CopyLevel3Positions)->Unit(benchmark::kMillisecond);

// 100 queries within 5 mm of the surface, the map service's batch size.
void BM_ClosestPoint100(benchmark::State& state) {
  const LoopSurface& surface = TenThousandFacesLevel3();
  std::mt19937_64 rng(42);
  std::uniform_int_distribution<int> vertex(0, static_cast<int>(surface.finest().positions.size()) - 1);
  std::uniform_real_distribution<double> offset(-5.0, 5.0);
  std::vector<Eigen::Vector3d> queries;
  for (int i = 0; i < 100; ++i) {
    queries.push_back(surface.finest().limit_positions[vertex(rng)] +
                      Eigen::Vector3d(offset(rng), offset(rng), offset(rng)));
  }
  for (auto _ : state) {
    for (const Eigen::Vector3d& q : queries) benchmark::DoNotOptimize(surface.ClosestPoint(q));
  }
  state.counters["finest_triangles"] = static_cast<double>(surface.finest().triangles.size());
}
BENCHMARK(BM_ClosestPoint100)->Unit(benchmark::kMicrosecond);

// Far-away queries (worst case for pruning).
void BM_ClosestPoint100Far(benchmark::State& state) {
  const LoopSurface& surface = TenThousandFacesLevel3();
  std::mt19937_64 rng(43);
  std::uniform_real_distribution<double> coordinate(-400.0, 400.0);
  std::vector<Eigen::Vector3d> queries;
  for (int i = 0; i < 100; ++i) queries.emplace_back(coordinate(rng), coordinate(rng), coordinate(rng));
  for (auto _ : state) {
    for (const Eigen::Vector3d& q : queries) benchmark::DoNotOptimize(surface.ClosestPoint(q));
  }
}
BENCHMARK(BM_ClosestPoint100Far)->Unit(benchmark::kMicrosecond);

// One 20 mm drag path in 0.25 mm steps (paper: 20 mm drags).
void BM_TraceDragPath20mm(benchmark::State& state) {
  const LoopSurface& surface = TenThousandFacesLevel3();
  const Eigen::Vector3d start(40.0, 0.0, 100.0);
  for (auto _ : state) {
    benchmark::DoNotOptimize(surface.TraceDragPath(start, Eigen::Vector3d(0, 1, 1), 20.0, 0.25));
  }
}
BENCHMARK(BM_TraceDragPath20mm)->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace surfmap

BENCHMARK_MAIN();
