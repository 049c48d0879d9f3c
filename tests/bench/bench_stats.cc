#include "tests/bench/bench_stats.h"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace surfmap::bench {

LatencySummary Summarize(std::vector<double> samples_ms) {
  LatencySummary s;
  if (samples_ms.empty()) return s;
  std::sort(samples_ms.begin(), samples_ms.end());
  auto rank = [&](double q) {
    const size_t index = static_cast<size_t>(std::ceil(q * samples_ms.size()));
    return samples_ms[std::clamp<size_t>(index, 1, samples_ms.size()) - 1];
  };
  s.count = static_cast<int>(samples_ms.size());
  s.mean_ms = std::accumulate(samples_ms.begin(), samples_ms.end(), 0.0) / samples_ms.size();
  s.p50_ms = rank(0.50);
  s.p99_ms = rank(0.99);
  s.max_ms = samples_ms.back();
  return s;
}

}  // namespace surfmap::bench
