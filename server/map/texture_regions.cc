#include "server/map/texture_regions.h"

#include <algorithm>
#include <array>
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
  static constexpr int kOrder = PieceStatistics::kMaxSignatureOrder;
  std::array<double, kOrder> rows{};        // sum of rows behind k_j
  std::array<double, kOrder> weighted_k{};  // sum of rows * k_j
  void Add(const PieceStatistics& p, double sign = 1.0) {
    const double w = 1.0 / (p.mu_se * p.mu_se);
    weight += sign * w;
    weighted_mu += sign * w * p.mu;
    pairs += sign * p.effective_pairs;
    weighted_var += sign * p.effective_pairs * p.spread * p.spread;
    for (int j = 0; j < std::min(p.signature_order, kOrder); ++j) {
      rows[j] += sign * p.reflection_rows[j];
      weighted_k[j] += sign * p.reflection_rows[j] * p.reflection[j];
    }
  }
  void Remove(const PieceStatistics& p) { Add(p, -1.0); }
  void Add(const Pool& o) {
    weight += o.weight;
    weighted_mu += o.weighted_mu;
    pairs += o.pairs;
    weighted_var += o.weighted_var;
    for (int j = 0; j < kOrder; ++j) {
      rows[j] += o.rows[j];
      weighted_k[j] += o.weighted_k[j];
    }
  }
  PieceStatistics Statistics() const {
    PieceStatistics s;
    s.mu = weighted_mu / weight;
    s.mu_se = 1.0 / std::sqrt(weight);
    s.effective_pairs = pairs;
    s.spread = std::sqrt(weighted_var / pairs);
    // A coefficient pooled over the pieces that have it (rows-weighted);
    // the signature ends at the first coefficient no piece has (rows below
    // half a value: what Remove leaves of a removed piece's rows).
    while (s.signature_order < kOrder && rows[s.signature_order] > 0.5) {
      const int j = s.signature_order++;
      s.reflection[j] = weighted_k[j] / rows[j];
      s.reflection_rows[j] = rows[j];
    }
    return s;
  }
};

double CriticalZ(const RegionMergeOptions& o) { return NormalUpperQuantile(0.5 * o.false_split_probability); }

// |log| of the ratio of two spreads, each at least spread_floor.
double SpreadLogRatio(const PieceStatistics& a, const PieceStatistics& b, const RegionMergeOptions& o) {
  return std::abs(std::log(std::max(a.spread, o.spread_floor) / std::max(b.spread, o.spread_floor)));
}

// How unlike two groups are, in multiples of what the rule allows (<= 1: alike).
double Unlikeness(const PieceStatistics& a, const PieceStatistics& b, const RegionMergeOptions& o, double z) {
  const double mu_allowed = std::max(o.mu_resolution, z * std::hypot(a.mu_se, b.mu_se));
  const double spread_allowed =
      std::max(std::log(o.spread_resolution), z * std::sqrt(0.5 / a.effective_pairs + 0.5 / b.effective_pairs));
  double unlike = std::max(std::abs(a.mu - b.mu) / mu_allowed, SpreadLogRatio(a, b, o) / spread_allowed);
  if (!o.compare_roughness) return unlike;
  for (int j = 0; j < std::min(a.signature_order, b.signature_order); ++j) {
    const double var = (1.0 - a.reflection[j] * a.reflection[j]) / a.reflection_rows[j] +
                       (1.0 - b.reflection[j] * b.reflection[j]) / b.reflection_rows[j];
    const double allowed =
        std::max(o.reflection_resolution, z * o.reflection_se_factor * std::sqrt(std::max(var, 0.0)));
    unlike = std::max(unlike, std::abs(a.reflection[j] - b.reflection[j]) / allowed);
  }
  return unlike;
}

// Alike however precisely both are known: every difference below its
// resolution.
bool WithinResolutions(const PieceStatistics& a, const PieceStatistics& b, const RegionMergeOptions& o) {
  if (std::abs(a.mu - b.mu) > o.mu_resolution) return false;
  if (SpreadLogRatio(a, b, o) > std::log(o.spread_resolution)) return false;
  if (!o.compare_roughness) return true;
  for (int j = 0; j < std::min(a.signature_order, b.signature_order); ++j) {
    if (std::abs(a.reflection[j] - b.reflection[j]) > o.reflection_resolution) return false;
  }
  return true;
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
  if (!(std::isfinite(spread_floor) && spread_floor >= 0.0)) return fail("spread_floor must be >= 0");
  if (!(std::isfinite(reflection_resolution) && reflection_resolution >= 0.0)) {
    return fail("reflection_resolution must be >= 0");
  }
  if (!(std::isfinite(reflection_se_factor) && reflection_se_factor >= 1.0)) {
    return fail("reflection_se_factor must be >= 1");
  }
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

namespace {

// Merges touching groups, most alike pieces first, while the merged groups
// stay alike and no pair in `apart` ends up in one group. `group` holds each
// piece's group on entry (any label; a piece alone is its own) and on exit.
void MergeGroups(const std::vector<PieceStatistics>& pieces, const std::vector<std::tuple<double, int, int>>& order,
                 const std::vector<std::pair<int, int>>& apart_pairs, const RegionMergeOptions& options, double z,
                 std::vector<int>& group) {
  const int n = static_cast<int>(pieces.size());
  Groups groups(n);
  {
    std::vector<int> first(n, -1);  // lowest piece of each label
    for (int i = 0; i < n; ++i) {
      if (first[group[i]] < 0) first[group[i]] = i;
      if (first[group[i]] != i) groups.Join(i, first[group[i]]);
    }
  }
  std::vector<Pool> pool(n);
  for (int i = 0; i < n; ++i) pool[groups.Find(i)].Add(pieces[i]);
  std::vector<std::set<int>> apart(n);  // by root
  for (const auto& [a, b] : apart_pairs) {
    const int ra = groups.Find(a), rb = groups.Find(b);
    if (ra == rb) continue;  // callers never ask for this
    apart[ra].insert(rb);
    apart[rb].insert(ra);
  }
  for (const auto& [unlike, a, b] : order) {
    const int ra = groups.Find(a), rb = groups.Find(b);
    if (ra == rb || apart[ra].count(rb)) continue;
    if (Unlikeness(pool[ra].Statistics(), pool[rb].Statistics(), options, z) > 1.0) continue;
    // Keep the lower index as the root; carry the pool and the apart sets.
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
  for (int i = 0; i < n; ++i) group[i] = groups.Find(i);
}

// Each group's pooled statistics, indexed by group label.
std::vector<Pool> GroupPools(const std::vector<PieceStatistics>& pieces, const std::vector<int>& group) {
  std::vector<Pool> pool(pieces.size());
  for (std::size_t i = 0; i < pieces.size(); ++i) pool[group[i]].Add(pieces[i]);
  return pool;
}

// The statistics of piece i's group without it.
PieceStatistics RestOfGroup(const std::vector<PieceStatistics>& pieces, const std::vector<int>& group,
                            const std::vector<Pool>& pool, int i) {
  Pool rest = pool[group[i]];
  rest.Remove(pieces[i]);
  return rest.Statistics();
}

// The piece of each group of >= 2 that is least like the rest of its group,
// if it is unlike them by the rule; pieces marked `stay` are not looked at.
std::vector<int> Misfits(const std::vector<PieceStatistics>& pieces, const std::vector<int>& group,
                         const std::vector<Pool>& pool, const RegionMergeOptions& options, double z,
                         const std::vector<char>& stay) {
  const int n = static_cast<int>(pieces.size());
  std::vector<int> size(n, 0);
  for (int i = 0; i < n; ++i) ++size[group[i]];
  std::vector<double> worst(n, 1.0);
  std::vector<int> misfit(n, -1);
  for (int i = 0; i < n; ++i) {
    const int g = group[i];
    if (size[g] < 2 || stay[i]) continue;
    const double unlike = Unlikeness(pieces[i], RestOfGroup(pieces, group, pool, i), options, z);
    if (unlike > worst[g]) {
      worst[g] = unlike;
      misfit[g] = i;
    }
  }
  std::vector<int> out;
  for (int m : misfit) {
    if (m >= 0) out.push_back(m);
  }
  return out;
}

}  // namespace

std::vector<int> MergeIntoRegions(const std::vector<PieceStatistics>& pieces,
                                  const std::vector<std::pair<int, int>>& adjacent,
                                  const std::vector<std::pair<int, int>>& cannot_link,
                                  const RegionMergeOptions& options) {
  const int n = static_cast<int>(pieces.size());
  const double z = CriticalZ(options);
  // Cannot-links count only where the pieces differ by more than the
  // resolutions.
  std::vector<std::pair<int, int>> apart;
  for (const auto& [a, b] : cannot_link) {
    if (a < 0 || b < 0 || a >= n || b >= n || a == b) continue;
    if (WithinResolutions(pieces[a], pieces[b], options)) continue;
    apart.emplace_back(a, b);
  }
  // Most alike pairs first; ties by index (deterministic).
  std::vector<std::tuple<double, int, int>> order;
  for (const auto& [a, b] : adjacent) {
    if (a < 0 || b < 0 || a >= n || b >= n || a == b) continue;
    order.emplace_back(Unlikeness(pieces[a], pieces[b], options, z), std::min(a, b), std::max(a, b));
  }
  std::sort(order.begin(), order.end());
  order.erase(std::unique(order.begin(), order.end()), order.end());
  std::vector<int> group(n);
  std::iota(group.begin(), group.end(), 0);
  const std::vector<std::pair<int, int>> known_apart = apart;
  MergeGroups(pieces, order, apart, options, z, group);
  // A piece unlike the rest of its group moves, for good, to a touching
  // group it is alike to and more alike to than to its own rest; with none,
  // it stays (a piece that straddles two textures is unlike both, and where
  // it lies is better told by the group it was merged with). One piece per
  // group per pass, the most unlike, since one misfit can make others look
  // unlike the rest. Each pass moves a piece for good or settles one, so
  // this ends; the cap only bounds the work.
  std::vector<std::vector<int>> neighbours(n);
  for (const auto& [unlike, a, b] : order) {
    neighbours[a].push_back(b);
    neighbours[b].push_back(a);
  }
  std::vector<char> stay(n, 0);  // misfits with nowhere better to go
  bool moved = false;
  for (int pass = 0; pass < n; ++pass) {
    const std::vector<Pool> pool = GroupPools(pieces, group);
    const std::vector<int> misfits = Misfits(pieces, group, pool, options, z, stay);
    if (misfits.empty()) break;
    std::vector<std::vector<int>> apart_from(n);  // each piece's partners in `apart`
    for (const auto& [a, b] : apart) {
      apart_from[a].push_back(b);
      apart_from[b].push_back(a);
    }
    std::vector<int> target(n, -1);  // the group a misfit moves to
    for (int m : misfits) {
      std::set<int> blocked;  // groups holding a piece kept apart from m
      for (int j : apart_from[m]) blocked.insert(group[j]);
      double best = std::min(1.0, Unlikeness(pieces[m], RestOfGroup(pieces, group, pool, m), options, z));
      for (int other : neighbours[m]) {
        const int g = group[other];
        if (g == group[m] || blocked.count(g) > 0) continue;
        const double unlike = Unlikeness(pieces[m], pool[g].Statistics(), options, z);
        if (unlike <= best) {
          best = unlike;
          target[m] = g;
        }
      }
      if (target[m] < 0) {
        stay[m] = 1;
        continue;
      }
      for (int i = 0; i < n; ++i) {
        if (i != m && group[i] == group[m]) apart.emplace_back(m, i);
      }
    }
    // Labels are any piece index (MergeGroups joins pieces of one label);
    // a moved piece takes its target's.
    for (int m : misfits) {
      if (target[m] < 0) continue;
      group[m] = target[m];
      moved = true;
    }
    MergeGroups(pieces, order, apart, options, z, group);
  }
  // Groups kept apart only by a moved piece may be alike as wholes: merge
  // them, now that each is tested with all its pieces.
  if (moved) MergeGroups(pieces, order, known_apart, options, z, group);
  std::vector<int> region(n, -1), number(n, -1);
  int next = 0;
  for (int i = 0; i < n; ++i) {
    const int r = group[i];
    if (number[r] < 0) number[r] = next++;
    region[i] = number[r];
  }
  return region;
}

}  // namespace surfmap
