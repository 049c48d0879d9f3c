// CoarsenFlat on a finely tessellated CAD box, against the dense-surface
// projection structure (BVH + vertex normals) a job builds from the same
// mesh anyway: the ratio says what the fallback adds to CreateJob.
#include <map>
#include <memory>

#include <benchmark/benchmark.h>
#include "server/mesh/dense_surface.h"
#include "server/mesh/flat_coarsen.h"
#include "server/mesh/flat_refine.h"
#include "server/mesh/primitive_meshes.h"

namespace surfmap {
namespace {

// A 100 mm box with facet edges of range(0) / 10 mm (2 mm: 49,154 vertices;
// 1 mm: 196,610).
const ControlMesh& FineBox(int tenths_mm) {
  static std::map<int, std::unique_ptr<ControlMesh>> meshes;
  std::unique_ptr<ControlMesh>& mesh = meshes[tenths_mm];
  if (!mesh) mesh = std::make_unique<ControlMesh>(*RefineFlat(MakeCadBox(50.0), tenths_mm / 10.0, 1000000));
  return *mesh;
}

void BM_CoarsenFlatFineBox(benchmark::State& state) {
  const ControlMesh& mesh = FineBox(static_cast<int>(state.range(0)));
  for (auto _ : state) {
    ControlMesh coarse = CoarsenFlat(mesh);
    benchmark::DoNotOptimize(coarse);
  }
  state.counters["vertices"] = static_cast<double>(mesh.positions.size());
}
BENCHMARK(BM_CoarsenFlatFineBox)->Arg(20)->Arg(10)->Unit(benchmark::kMillisecond);

void BM_DenseSurfaceFineBox(benchmark::State& state) {
  const ControlMesh& mesh = FineBox(static_cast<int>(state.range(0)));
  for (auto _ : state) {
    DenseSurface dense(mesh);
    benchmark::DoNotOptimize(dense);
  }
  state.counters["vertices"] = static_cast<double>(mesh.positions.size());
}
BENCHMARK(BM_DenseSurfaceFineBox)->Arg(20)->Arg(10)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace surfmap

BENCHMARK_MAIN();
