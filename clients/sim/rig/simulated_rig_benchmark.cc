// Speed of the simulated rig: building the bottle rig (Loop level 3) and
// executing one 20 mm probe (surface walk + drag simulation).
#include <benchmark/benchmark.h>
#include "clients/sim/rig/simulated_rig.h"

namespace surfmap {
namespace {

void BM_CreateBottleRig(benchmark::State& state) {
  auto scene = LoadSceneByName("bottle");
  if (!scene.ok()) {
    state.SkipWithError(std::string(scene.status().message()).c_str());
    return;
  }
  for (auto _ : state) {
    auto rig = SimulatedRig::Create(*scene);
    benchmark::DoNotOptimize(rig);
  }
}
BENCHMARK(BM_CreateBottleRig)->Unit(benchmark::kMillisecond);

void BM_ExecuteProbe(benchmark::State& state) {
  auto scene = LoadSceneByName("bottle");
  if (!scene.ok()) {
    state.SkipWithError(std::string(scene.status().message()).c_str());
    return;
  }
  auto rig = SimulatedRig::Create(*std::move(scene));
  ProbeRequest request;
  request.position = {-40, 0, 100};
  request.normal = {-1, 0, 0};
  request.drag_direction = {0, -1, 0};
  std::int64_t id = 0;
  for (auto _ : state) {
    request.command_id = ++id;
    auto trace = (*rig)->Execute(request);
    benchmark::DoNotOptimize(trace);
  }
}
BENCHMARK(BM_ExecuteProbe)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace surfmap

BENCHMARK_MAIN();
