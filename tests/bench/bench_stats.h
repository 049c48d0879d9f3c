// Latency summaries for the benchmark client.
#pragma once

#include <chrono>
#include <vector>

namespace surfmap::bench {

struct LatencySummary {
  int count = 0;
  double mean_ms = 0.0;
  double p50_ms = 0.0;
  double p99_ms = 0.0;
  double max_ms = 0.0;
};

// Nearest-rank percentiles of `samples_ms` (copied and sorted); all zero
// when empty.
LatencySummary Summarize(std::vector<double> samples_ms);

// A steady-clock duration in milliseconds.
inline double Ms(std::chrono::steady_clock::duration d) {
  return std::chrono::duration<double, std::milli>(d).count();
}

}  // namespace surfmap::bench
