#include "server/map/nearest_labels.h"

#include <functional>
#include <limits>
#include <queue>
#include <tuple>

namespace surfmap {

NearestLabels FindNearestLabels(const SurfaceLevel& level, std::span<const LabelledSeed> seeds) {
  const int nv = static_cast<int>(level.limit_positions.size());
  constexpr double kInf = std::numeric_limits<double>::infinity();
  NearestLabels out;
  out.label.assign(nv, {-1, -1});
  out.distance_mm.assign(nv, {kInf, kInf});
  out.seed.assign(nv, {-1, -1});
  // (distance, seed index, vertex): the seed index second makes ties
  // deterministic; the label is the seed's.
  using Entry = std::tuple<double, int, int>;
  std::priority_queue<Entry, std::vector<Entry>, std::greater<Entry>> queue;
  for (int s = 0; s < static_cast<int>(seeds.size()); ++s) {
    const LabelledSeed& seed = seeds[s];
    if (seed.vertex < 0 || seed.vertex >= nv || seed.label < 0) continue;
    queue.emplace((level.limit_positions[seed.vertex] - seed.point).norm(), s, seed.vertex);
  }
  const int rows = static_cast<int>(level.neighbors.size());
  while (!queue.empty()) {
    const auto [d, s, v] = queue.top();
    queue.pop();
    const int label = seeds[s].label;
    auto& labels = out.label[v];
    // A vertex takes a label once (its nearest seed of that label reaches it
    // first) and at most two labels.
    if (labels[0] == label || labels[1] == label || labels[1] != -1) continue;
    const int slot = labels[0] == -1 ? 0 : 1;
    labels[slot] = label;
    out.distance_mm[v][slot] = d;
    out.seed[v][slot] = s;
    if (v >= rows) continue;
    for (int u : level.neighbors[v]) {
      if (u < 0 || u >= nv) continue;
      const auto& there = out.label[u];
      if (there[1] != -1 || there[0] == label) continue;
      queue.emplace((level.limit_positions[u] - seeds[s].point).norm(), s, u);
    }
  }
  return out;
}

}  // namespace surfmap
