// The renderer at haptic rates on a realistic map: the bottle scene (Lloyd &
// Pai's glass bottle with sandpaper patches) at Loop level 4, 40960
// triangles, with its true textures. A probe slides over the body along a
// wandering path at 50 mm/s sampled at 1 kHz (0.05 mm per sample, a quick
// hand), precomputed so the loop measures only the renderer:
//   BM_LocateCoherent   the surface lookup alone, with the last-triangle hint
//   BM_LocateCold       the lookup without a hint (every query from scratch)
//   BM_Sample           the whole haptic sample: lookup + mu + AR texture
// items_per_second is samples per second on one core; the issue asks >= 10k.
#include <benchmark/benchmark.h>

#include <random>

#include "server/haptics/model_drag.h"
#include "clients/haptics/scene/scene_texture_map.h"
#include "server/haptics/texture_renderer.h"
#include "clients/sim/rig/scene.h"

namespace surfmap::haptics {
namespace {

struct Fixture {
  std::unique_ptr<TextureRenderer> renderer;
  std::vector<Eigen::Vector3d> positions;  // probe positions, 0.05 mm apart
  std::vector<Eigen::Vector3d> velocities;
};

const Fixture& Bottle() {
  static const Fixture* fixture = [] {
    auto* f = new Fixture;
    absl::StatusOr<Scene> scene = LoadSceneByName("bottle");
    if (!scene.ok()) std::abort();
    auto surface = LoopSurface::Create(scene->mesh, 4);
    if (!surface.ok()) std::abort();
    f->renderer = *TextureRenderer::Create(SceneTruthTextureMap(*scene, **surface, 4));
    // A wandering path over the body: 40 legs of 5 mm in seeded directions,
    // traced on the model, then resampled at 0.05 mm; the probe rides 0.02 mm
    // above the mesh (a penetration-free haptic proxy would be on it).
    std::mt19937_64 rng(5);
    std::uniform_real_distribution<double> angle(0.0, 6.283185307179586);
    Eigen::Vector3d start(40.0, 0.0, 60.0);
    for (int leg = 0; leg < 40; ++leg) {
      const double a = angle(rng);
      auto path = TraceModelPath(*f->renderer, start, {0.0, std::cos(a), std::sin(a)}, 5.0, 0.05);
      if (!path.ok() || path->size() < 2) continue;
      for (size_t i = 1; i < path->size(); ++i) {
        const Eigen::Vector3d d = (*path)[i] - (*path)[i - 1];
        ProbeState s;
        const SurfaceLookup hit = f->renderer->Locate((*path)[i], s);
        f->positions.push_back((*path)[i] + 0.02 * hit.normal);
        f->velocities.push_back(d.normalized() * 50.0);
      }
      start = path->back();
    }
    return f;
  }();
  return *fixture;
}

void BM_LocateCoherent(benchmark::State& state) {
  const Fixture& f = Bottle();
  ProbeState probe;
  size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(f.renderer->Locate(f.positions[i], probe));
    if (++i == f.positions.size()) i = 0;
  }
  state.SetItemsProcessed(state.iterations());
  state.counters["triangles"] = static_cast<double>(f.renderer->map().triangles.size());
}
BENCHMARK(BM_LocateCoherent);

void BM_LocateCold(benchmark::State& state) {
  const Fixture& f = Bottle();
  size_t i = 0;
  for (auto _ : state) {
    ProbeState probe;  // no hint
    benchmark::DoNotOptimize(f.renderer->Locate(f.positions[i], probe));
    i = (i + 97) % f.positions.size();
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_LocateCold);

void BM_Sample(benchmark::State& state) {
  const Fixture& f = Bottle();
  ProbeState probe;
  size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(f.renderer->Sample(probe, f.positions[i], f.velocities[i], 3.0));
    if (++i == f.positions.size()) i = 0;
  }
  state.SetItemsProcessed(state.iterations());
  state.counters["path_samples"] = static_cast<double>(f.positions.size());
}
BENCHMARK(BM_Sample);

}  // namespace
}  // namespace surfmap::haptics

BENCHMARK_MAIN();
