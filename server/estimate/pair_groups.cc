#include "server/estimate/pair_groups.h"

#include <algorithm>
#include <cmath>

namespace surfmap {

int PairsPerGroup(std::span<const double> s_mm, double spacing_mm) {
  if (!(spacing_mm > 0.0) || s_mm.size() < 2) return 1;
  std::vector<double> gaps;
  gaps.reserve(s_mm.size() - 1);
  for (std::size_t i = 1; i < s_mm.size(); ++i) gaps.push_back(s_mm[i] - s_mm[i - 1]);
  const auto mid = gaps.begin() + gaps.size() / 2;
  std::nth_element(gaps.begin(), mid, gaps.end());
  if (!(*mid > 0.0)) return 1;
  const double k = std::floor(spacing_mm / *mid + 0.5);
  // Never more groups than pairs allow: at least two groups.
  return static_cast<int>(std::clamp(k, 1.0, std::max(1.0, std::floor(s_mm.size() / 2.0))));
}

PairGroups AveragePairGroups(std::span<const double> s_mm, std::span<const double> values, int k) {
  k = std::max(k, 1);
  const std::size_t n = std::min(s_mm.size(), values.size());
  PairGroups out;
  const std::size_t groups = std::max<std::size_t>(n / k, n > 0 ? 1 : 0);
  out.s_mm.reserve(groups);
  out.values.reserve(groups);
  for (std::size_t g = 0; g < groups; ++g) {
    const std::size_t a = g * k, b = g + 1 == groups ? n : a + k;
    double s = 0.0, v = 0.0;
    for (std::size_t i = a; i < b; ++i) s += s_mm[i], v += values[i];
    out.s_mm.push_back(s / static_cast<double>(b - a));
    out.values.push_back(v / static_cast<double>(b - a));
  }
  return out;
}

std::vector<ChangePoint> ChangesOfPairs(const std::vector<ChangePoint>& group_changes, std::span<const double> pair_s_mm,
                                        int k) {
  k = std::max(k, 1);
  std::vector<ChangePoint> out = group_changes;
  for (ChangePoint& c : out) {
    c.index *= k;
    if (c.index >= 1 && c.index < static_cast<int>(pair_s_mm.size())) {
      c.s_mm = 0.5 * (pair_s_mm[c.index - 1] + pair_s_mm[c.index]);
    }
  }
  return out;
}

}  // namespace surfmap
