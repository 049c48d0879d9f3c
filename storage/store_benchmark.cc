// AcceptTrace throughput: N rig threads each submitting 1,000-sample traces
// and waiting for each to be durable (synchronous=FULL, fsync before return),
// with group commit on and off, in the same run. Prints traces/s per case and
// the group-commit speed-up at the end.
//
//   build-*/storage/store_benchmark [--benchmark_filter=...]
//   SURFMAP_BENCH_DIR=/some/dir to put the database elsewhere (default: /tmp).
//   SURFMAP_BENCH_BACKGROUND_CHECKPOINT=0 to checkpoint on the writer thread.
//   SURFMAP_BENCH_PAGE_SIZE=4096 to compare page sizes (default 16384).
#include <atomic>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <mutex>

#include "absl/strings/str_cat.h"
#include "benchmark/benchmark.h"
#include "storage/sqlite_store.h"
#include "storage/store_test_support_for_test.h"

namespace surfmap {
namespace {

constexpr int kSamplesPerTrace = 1000;
constexpr int kTracesPerCase = 3200;

struct Case {
  std::unique_ptr<SqliteStore> store;
  std::vector<CommandRecord> commands;  // leased, one per trace to submit
  std::atomic<size_t> next{0};
  std::filesystem::path dir;
};

Case* g_case = nullptr;
std::mutex g_results_mu;
std::map<std::pair<int, bool>, double> g_traces_per_s;  // (threads, group commit)

bool BackgroundCheckpoint() {
  const char* v = std::getenv("SURFMAP_BENCH_BACKGROUND_CHECKPOINT");
  return v == nullptr || std::string(v) != "0";
}

void SetUpCase(bool group_commit, int n_traces) {
  g_case = new Case;
  const char* base = std::getenv("SURFMAP_BENCH_DIR");
  g_case->dir = std::filesystem::path(base ? base : "/tmp") /
                absl::StrCat("surfmap-store-bench-", getpid());
  std::filesystem::remove_all(g_case->dir);
  std::filesystem::create_directories(g_case->dir);
  SqliteStoreOptions options;
  options.writer.group_commit = group_commit;
  options.background_checkpoint = BackgroundCheckpoint();
  if (const char* ps = std::getenv("SURFMAP_BENCH_PAGE_SIZE")) options.page_size = std::atoi(ps);
  auto store = SqliteStore::Open((g_case->dir / "bench.db").string(), options);
  if (!store.ok()) {
    std::fprintf(stderr, "open: %s\n", store.status().ToString().c_str());
    std::abort();
  }
  g_case->store = std::move(*store);
  absl::StatusOr<CreatedJob> job = MakeTestJob(*g_case->store, n_traces);
  if (!job.ok()) std::abort();
  // Lease everything in one statement: the benchmark times AcceptTrace only.
  auto db = SqliteConnection::Open((g_case->dir / "bench.db").string(), {});
  if (!db.ok() || !(*db)->Exec("UPDATE commands SET state = 'leased', lease_owner = 'bench', "
                               "lease_deadline_unix_ms = 9e15, attempt = 1").ok()) {
    std::abort();
  }
  g_case->commands = *g_case->store->ListCommands(job->job.id);
}

void TearDownCase() {
  std::filesystem::path dir = g_case->dir;
  delete g_case;
  g_case = nullptr;
  std::filesystem::remove_all(dir);
}

void BM_AcceptTrace(benchmark::State& state) {
  const bool group_commit = state.range(0) != 0;
  if (state.thread_index() == 0) SetUpCase(group_commit, kTracesPerCase);
  // Each rig sends its own pre-built trace (building it is the rig's cost).
  std::vector<StoredSample> samples = MakeTestSamples(kSamplesPerTrace, 1000 + state.thread_index());
  int64_t failures = 0;
  for (auto _ : state) {  // the loop start is a barrier: set-up is done
    const CommandRecord& command = g_case->commands[g_case->next.fetch_add(1)];
    AcceptTraceRequest request;
    request.command_id = command.id;
    request.job_id = command.job_id;
    request.samples = samples;
    request.fit = MakeTestFit(0.13);
    request.events.push_back(NewEvent{"trace_accepted", "{}"});
    absl::StatusOr<AcceptTraceResult> result = g_case->store->AcceptTrace(std::move(request));
    if (!result.ok()) ++failures;
  }
  state.SetItemsProcessed(state.iterations());
  state.counters["failures"] = benchmark::Counter(static_cast<double>(failures),
                                                  benchmark::Counter::kAvgThreads);
  if (state.thread_index() == 0) {
    GroupCommitStats stats = g_case->store->writer_stats();
    // Commands leased by one UPDATE; the writer's transactions here are the
    // job creation plus the traces.
    state.counters["avg_batch"] =
        static_cast<double>(stats.writes) / static_cast<double>(std::max<int64_t>(1, stats.transactions));
    state.counters["largest_batch"] = static_cast<double>(stats.largest_batch);
  }
}

// Fixed iteration counts so that every case writes the same number of traces.
void Register() {
  for (int threads : {1, 4, 16}) {
    for (int gc : {0, 1}) {
      benchmark::RegisterBenchmark(
          absl::StrCat("AcceptTrace/", gc ? "group_commit" : "commit_per_trace").c_str(),
          BM_AcceptTrace)
          ->Arg(gc)
          ->Threads(threads)
          ->Iterations(kTracesPerCase / threads)
          ->UseRealTime()
          ->Unit(benchmark::kMicrosecond);
    }
  }
}

class RatioReporter : public benchmark::ConsoleReporter {
 public:
  void ReportRuns(const std::vector<Run>& runs) override {
    ConsoleReporter::ReportRuns(runs);
    for (const Run& run : runs) {
      auto it = run.counters.find("items_per_second");
      if (it == run.counters.end()) continue;
      const bool gc = run.benchmark_name().find("group_commit") != std::string::npos;
      std::lock_guard<std::mutex> lock(g_results_mu);
      g_traces_per_s[{static_cast<int>(run.threads), gc}] = it->second.value;
    }
    // The case is over (all threads left the loop): free it for the next one.
    if (g_case != nullptr) TearDownCase();
  }
};

}  // namespace
}  // namespace surfmap

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  surfmap::Register();
  surfmap::RatioReporter reporter;
  benchmark::RunSpecifiedBenchmarks(&reporter);
  std::printf("\n%-8s %18s %18s %8s\n", "threads", "commit/trace tr/s", "group commit tr/s",
              "ratio");
  for (int threads : {1, 4, 16}) {
    auto off = surfmap::g_traces_per_s.find({threads, false});
    auto on = surfmap::g_traces_per_s.find({threads, true});
    if (off == surfmap::g_traces_per_s.end() || on == surfmap::g_traces_per_s.end()) continue;
    std::printf("%-8d %18.0f %18.0f %8.2f\n", threads, off->second, on->second,
                on->second / off->second);
  }
  benchmark::Shutdown();
  return 0;
}
