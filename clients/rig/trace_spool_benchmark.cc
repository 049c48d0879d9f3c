// What the spool costs a rig per trace: writing a measured trace (format,
// read-back check, temp file, fsync, rename, directory fsync) and deleting it
// after the server's OK (unlink, directory fsync), on a 1,013-sample trace as
// the simulated rig measures a 45 mm drag. The directory is under
// $TMPDIR (default /tmp): run with TMPDIR on the disk a rig would use.
// BM_SpoolAddThenRemoveDurably adds the directory fsync after the delete that
// Remove leaves out, to time what leaving it out saves.
#include <fcntl.h>
#include <stdlib.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>

#include <benchmark/benchmark.h>
#include "clients/rig/trace_spool.h"

namespace surfmap::rig {
namespace {

DragTrace LongTrace() {
  DragTrace trace;
  for (int i = 0; i < 1013; ++i) {
    DragSample s;
    s.t = 0.01 * i;
    const double x = i < 500 ? 0.09 * i : i < 513 ? 45.0 : 45.0 - 0.09 * (i - 513);
    s.position = Eigen::Vector3d(x + 1e-3 * std::sin(i), 0.5 * std::cos(0.1 * i), 1e-4 * i);
    s.force = Eigen::Vector3d(i < 500 ? -1.5 : 1.5, 0.01 * std::sin(0.3 * i), 5.0 + 0.07 * std::cos(0.7 * i));
    s.phase = i < 500 ? DragPhase::kForward : i < 513 ? DragPhase::kPause : DragPhase::kReverse;
    trace.samples.push_back(s);
  }
  return trace;
}

// The directory fsync Remove leaves out (it used to make the delete durable),
// so both variants are timed in the same run: --benchmark_enable_random_interleaving.
void SyncDirectory(const std::string& dir) {
  const int fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd >= 0) {
    ::fsync(fd);
    ::close(fd);
  }
}

void SpoolAddThenRemove(benchmark::State& state, bool durable_remove) {
  std::string pattern = (std::filesystem::temp_directory_path() / "surfmap-spool-bench-XXXXXX").string();
  if (mkdtemp(pattern.data()) == nullptr) {
    state.SkipWithError("mkdtemp failed");
    return;
  }
  {
    auto spool = TraceSpool::Open(pattern);
    if (!spool.ok()) {
      state.SkipWithError(std::string(spool.status().message()).c_str());
      return;
    }
    const DragTrace trace = LongTrace();
    SpoolHeader header;
    header.job_id = 1;
    header.rig_id = "bench";
    for (auto _ : state) {
      header.command_id += 1;
      header.measured_unix_ms = header.command_id;
      auto file = (*spool)->Add(header, trace);
      if (!file.ok() || !(*spool)->Remove(*file).ok()) {
        state.SkipWithError("spool write failed");
        break;
      }
      if (durable_remove) SyncDirectory(pattern);
    }
  }
  std::error_code ignored;
  std::filesystem::remove_all(pattern, ignored);
}
void BM_SpoolAddThenRemove(benchmark::State& state) { SpoolAddThenRemove(state, false); }
void BM_SpoolAddThenRemoveDurably(benchmark::State& state) { SpoolAddThenRemove(state, true); }
BENCHMARK(BM_SpoolAddThenRemove)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_SpoolAddThenRemoveDurably)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace surfmap::rig

BENCHMARK_MAIN();
