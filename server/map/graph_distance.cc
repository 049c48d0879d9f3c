#include "server/map/graph_distance.h"

#include <functional>
#include <limits>
#include <queue>
#include <tuple>

namespace surfmap {

NearestSource NearestSourceDistance(const SurfaceLevel& level, std::span<const int> sources) {
  const int nv = static_cast<int>(level.limit_positions.size());
  NearestSource out;
  out.distance_mm.assign(nv, std::numeric_limits<double>::infinity());
  out.source.assign(nv, -1);
  // (distance, source index, vertex): ordering by source index second makes
  // ties deterministic.
  using Entry = std::tuple<double, int, int>;
  std::priority_queue<Entry, std::vector<Entry>, std::greater<Entry>> queue;
  for (int s = 0; s < static_cast<int>(sources.size()); ++s) {
    const int v = sources[s];
    if (v < 0 || v >= nv) continue;
    if (out.source[v] != -1) continue;  // a repeated source: the first one wins
    out.distance_mm[v] = 0.0;
    out.source[v] = s;
    queue.emplace(0.0, s, v);
  }
  const int neighbor_rows = static_cast<int>(level.neighbors.size());
  while (!queue.empty()) {
    auto [d, s, v] = queue.top();
    queue.pop();
    if (d > out.distance_mm[v] || (d == out.distance_mm[v] && s != out.source[v])) continue;
    if (v >= neighbor_rows) continue;
    for (int u : level.neighbors[v]) {
      if (u < 0 || u >= nv) continue;
      const double nd = d + (level.limit_positions[u] - level.limit_positions[v]).norm();
      if (nd < out.distance_mm[u] || (nd == out.distance_mm[u] && s < out.source[u])) {
        out.distance_mm[u] = nd;
        out.source[u] = s;
        queue.emplace(nd, s, u);
      }
    }
  }
  return out;
}

}  // namespace surfmap
