// FitTrace and ParseTraceCsv on one simulated ~1,000-sample drag trace
// (45 mm at 10 mm/s and 100 Hz: 481 forward + 50 pause + 481 reverse samples).
#include <string>

#include <benchmark/benchmark.h>
#include "clients/sim/dragsim/drag_geometry.h"
#include "clients/sim/dragsim/drag_simulator.h"
#include "server/estimate/fit_trace.h"
#include "server/estimate/trace_csv.h"

namespace surfmap {
namespace {

const DragTrace& Trace() {
  static const DragTrace trace = [] {
    DragSimOptions options;
    options.seed = 7;
    options.length_mm = 45.0;
    return SimulateDrag(CylinderGeometry(40.0, 45.0), UniformMaterial(kRubber), options)->trace;
  }();
  return trace;
}

// Arg: FitOptions::noise_replicates (4, the default, against 0, the white
// noise model without propagation: the cost of series_noise.h).
void BM_FitTrace(benchmark::State& state) {
  const DragTrace& trace = Trace();
  FitOptions options;
  options.noise_replicates = static_cast<int>(state.range(0));
  for (auto _ : state) {
    absl::StatusOr<TraceFit> fit = FitTrace(trace, options);
    benchmark::DoNotOptimize(fit);
    if (!fit.ok()) state.SkipWithError(std::string(fit.status().message()).c_str());
  }
  state.SetItemsProcessed(state.iterations());  // items = traces
  state.counters["samples"] = static_cast<double>(trace.samples.size());
}
BENCHMARK(BM_FitTrace)->Arg(4)->Arg(0);

void BM_ParseTraceCsv(benchmark::State& state) {
  const std::string text = FormatTraceCsv(Trace());
  for (auto _ : state) {
    absl::StatusOr<DragTrace> trace = ParseTraceCsv(text, "bench.csv");
    benchmark::DoNotOptimize(trace);
  }
  state.SetItemsProcessed(state.iterations());
  state.SetBytesProcessed(state.iterations() * static_cast<int64_t>(text.size()));
}
BENCHMARK(BM_ParseTraceCsv);

void BM_FormatTraceCsv(benchmark::State& state) {
  const DragTrace& trace = Trace();
  for (auto _ : state) benchmark::DoNotOptimize(FormatTraceCsv(trace));
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_FormatTraceCsv);

}  // namespace
}  // namespace surfmap

BENCHMARK_MAIN();
