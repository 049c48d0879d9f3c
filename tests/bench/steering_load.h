// Benchmarks of the service staying live under mixed load (the concurrency
// issue's figures), each measured against a baseline in the same run:
//   - watchers: acknowledged traces/s of `rigs` rigs with and without
//     `watchers` WatchJob(include_map) streams open, in alternating phases;
//   - reads under heavy calls: GetJob latency alone, then while `heavy`
//     GetSample(include_series) calls on a ~1,000,000-sample trace run.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "server/estimate/drag_trace.h"
#include "tests/bench/bench_stats.h"

namespace surfmap::bench {

struct WatcherLoadResult {
  std::vector<double> rate_without;  // traces/s per phase without watchers
  std::vector<double> rate_with;     // ... with the watchers open
  int64_t updates = 0;               // updates the watchers received (with maps)
};

// Alternates `rounds` pairs of phases of `seconds` each on one uniform job.
WatcherLoadResult RunWatcherLoad(const std::string& address, int64_t object_id, const std::vector<DragTrace>& templates,
                                 int rigs, int watchers, int rounds, double seconds, int level);

struct ReadLatencyResult {
  LatencySummary get_job_alone;
  LatencySummary get_job_under_load;
  int heavy_calls = 0;        // GetSample(include_series) calls completed meanwhile
  int64_t trace_samples = 0;  // samples of the big trace
  double heavy_mean_ms = 0.0;
  std::string error;
};

// Submits one trace of about `samples` samples (streamed), then measures.
ReadLatencyResult RunReadLatency(const std::string& address, int64_t object_id, int64_t samples, int heavy,
                                 double seconds);

}  // namespace surfmap::bench
