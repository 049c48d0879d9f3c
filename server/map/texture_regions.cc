#include "server/map/texture_regions.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <set>
#include <tuple>

#include "absl/strings/str_cat.h"
#include "server/estimate/normal_quantile.h"

namespace surfmap {
namespace {

// Running pooled statistics of a group.
struct Pool {
  double weight = 0.0;        // sum of 1 / se^2
  double weighted_mu = 0.0;   // sum of mu / se^2
  double pairs = 0.0;         // sum of effective pairs
  double weighted_var = 0.0;  // sum of pairs * spread^2
  void Add(const PieceStatistics& p) {
    const double w = 1.0 / (p.mu_se * p.mu_se);
    weight += w;
    weighted_mu += w * p.mu;
    pairs += p.effective_pairs;
    weighted_var += p.effective_pairs * p.spread * p.spread;
  }
  void Add(const Pool& o) {
    weight += o.weight;
    weighted_mu += o.weighted_mu;
    pairs += o.pairs;
    weighted_var += o.weighted_var;
  }
  PieceStatistics Statistics() const {
    PieceStatistics s;
    s.mu = weighted_mu / weight;
    s.mu_se = 1.0 / std::sqrt(weight);
    s.effective_pairs = pairs;
    s.spread = std::sqrt(weighted_var / pairs);
    return s;
  }
};

double CriticalZ(const RegionMergeOptions& o) { return NormalUpperQuantile(0.5 * o.false_split_probability); }

// How unlike two groups are, in multiples of what the rule allows (<= 1: alike).
double Unlikeness(const PieceStatistics& a, const PieceStatistics& b, const RegionMergeOptions& o, double z) {
  const double mu_allowed = std::max(o.mu_resolution, z * std::hypot(a.mu_se, b.mu_se));
  const double spread_allowed =
      std::max(std::log(o.spread_resolution), z * std::sqrt(0.5 / a.effective_pairs + 0.5 / b.effective_pairs));
  return std::max(std::abs(a.mu - b.mu) / mu_allowed, std::abs(std::log(a.spread / b.spread)) / spread_allowed);
}

class Groups {
 public:
  explicit Groups(int n) : parent_(n) { std::iota(parent_.begin(), parent_.end(), 0); }
  int Find(int x) {
    while (parent_[x] != x) x = parent_[x] = parent_[parent_[x]];
    return x;
  }
  void Join(int child, int root) { parent_[child] = root; }

 private:
  std::vector<int> parent_;
};

}  // namespace

bool RegionMergeOptions::IsValid(std::string* why) const {
  auto fail = [why](std::string m) {
    if (why != nullptr) *why = std::move(m);
    return false;
  };
  if (!(false_split_probability > 0.0 && false_split_probability < 1.0)) {
    return fail(absl::StrCat("false_split_probability ", false_split_probability, " must be in (0, 1)"));
  }
  if (!(std::isfinite(mu_resolution) && mu_resolution >= 0.0)) return fail("mu_resolution must be >= 0");
  if (!(std::isfinite(spread_resolution) && spread_resolution >= 1.0)) return fail("spread_resolution must be >= 1");
  return true;
}

bool TexturesAlike(const PieceStatistics& a, const PieceStatistics& b, const RegionMergeOptions& options) {
  return Unlikeness(a, b, options, CriticalZ(options)) <= 1.0;
}

PieceStatistics PoolStatistics(const std::vector<PieceStatistics>& pieces) {
  Pool pool;
  for (const PieceStatistics& p : pieces) pool.Add(p);
  return pool.Statistics();
}

std::vector<int> MergeIntoRegions(const std::vector<PieceStatistics>& pieces,
                                  const std::vector<std::pair<int, int>>& adjacent,
                                  const std::vector<std::pair<int, int>>& cannot_link,
                                  const RegionMergeOptions& options) {
  const int n = static_cast<int>(pieces.size());
  const double z = CriticalZ(options);
  std::vector<Pool> pool(n);
  for (int i = 0; i < n; ++i) pool[i].Add(pieces[i]);
  // Cannot-links between groups, by root; only those whose pieces differ by
  // more than the resolutions count.
  std::vector<std::set<int>> apart(n);
  for (const auto& [a, b] : cannot_link) {
    if (a < 0 || b < 0 || a >= n || b >= n || a == b) continue;
    const double dmu = std::abs(pieces[a].mu - pieces[b].mu);
    const double dspread = std::abs(std::log(pieces[a].spread / pieces[b].spread));
    if (dmu <= options.mu_resolution && dspread <= std::log(options.spread_resolution)) continue;
    apart[a].insert(b);
    apart[b].insert(a);
  }
  // Most alike pairs first; ties by index (deterministic).
  std::vector<std::tuple<double, int, int>> order;
  for (const auto& [a, b] : adjacent) {
    if (a < 0 || b < 0 || a >= n || b >= n || a == b) continue;
    order.emplace_back(Unlikeness(pieces[a], pieces[b], options, z), std::min(a, b), std::max(a, b));
  }
  std::sort(order.begin(), order.end());
  order.erase(std::unique(order.begin(), order.end()), order.end());
  Groups groups(n);
  for (const auto& [unlike, a, b] : order) {
    const int ra = groups.Find(a), rb = groups.Find(b);
    if (ra == rb || apart[ra].count(rb)) continue;
    if (Unlikeness(pool[ra].Statistics(), pool[rb].Statistics(), options, z) > 1.0) continue;
    // Keep the lower index as the root; carry the pool and the cannot-links.
    const int root = std::min(ra, rb), child = std::max(ra, rb);
    groups.Join(child, root);
    pool[root].Add(pool[child]);
    for (int other : apart[child]) {
      apart[other].erase(child);
      apart[other].insert(root);
      apart[root].insert(other);
    }
    apart[child].clear();
  }
  std::vector<int> region(n, -1), number(n, -1);
  int next = 0;
  for (int i = 0; i < n; ++i) {
    const int r = groups.Find(i);
    if (number[r] < 0) number[r] = next++;
    region[i] = number[r];
  }
  return region;
}

}  // namespace surfmap
