#include "server/estimate/change_points.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <utility>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"

namespace surfmap {
namespace {

constexpr int kLags = 2;                   // AR(2): the texture model of docs/method.md section 3
constexpr int kParameters = kLags + 2;     // intercept, a1, a2, innovation variance
constexpr int kSums = 10;

// Prefix sums over rows t (t >= kLags) of the products an AR(2) regression
// with intercept needs: y = x_t on z = (1, x_(t-1), x_(t-2)). The values are
// centred on their mean first (conditioning).
class ArRowSums {
 public:
  using Sums = std::array<double, kSums>;  // 1, z1, z2, z1z1, z2z2, z1z2, y, yz1, yz2, yy

  explicit ArRowSums(std::span<const double> x) : prefix_(x.size() + 1, Sums{}) {
    double mean = 0.0;
    for (double v : x) mean += v;
    mean /= std::max<std::size_t>(1, x.size());
    double mean_square = 0.0;
    for (std::size_t t = 0; t < x.size(); ++t) {
      Sums row{};
      if (t >= kLags) {
        const double y = x[t] - mean, z1 = x[t - 1] - mean, z2 = x[t - 2] - mean;
        row = {1.0, z1, z2, z1 * z1, z2 * z2, z1 * z2, y, y * z1, y * z2, y * y};
      }
      for (int q = 0; q < kSums; ++q) prefix_[t + 1][q] = prefix_[t][q] + row[q];
      mean_square += (x[t] - mean) * (x[t] - mean);
    }
    // Below this a residual variance is rounding residue: exactly constant
    // stretches (noise-free synthetic data) must not make log(RSS) -inf.
    variance_floor_ = 1e-20 * mean_square / std::max<std::size_t>(1, x.size()) + 1e-300;
  }

  // Sums over the rows whose lags stay inside [a, b): t in [a + 2, b).
  Sums Rows(int a, int b) const {
    Sums s{};
    if (b - a <= kLags) return s;
    for (int q = 0; q < kSums; ++q) s[q] = prefix_[b][q] - prefix_[a + kLags][q];
    return s;
  }

  // Residual sum of squares of the least-squares fit on `s` (floored): with
  // the intercept eliminated, RSS = Syy - b' Szz^-1 b over the centred
  // moments, a 2 x 2 solve in closed form (this runs ~3 times per candidate).
  double Rss(const Sums& s) const {
    const double n = s[0];
    const double inv_n = 1.0 / n;
    const double a = s[3] - s[1] * s[1] * inv_n;   // z1 z1
    const double c = s[4] - s[2] * s[2] * inv_n;   // z2 z2
    const double b = s[5] - s[1] * s[2] * inv_n;   // z1 z2
    const double b1 = s[7] - s[6] * s[1] * inv_n;  // y z1
    const double b2 = s[8] - s[6] * s[2] * inv_n;  // y z2
    const double yy = s[9] - s[6] * s[6] * inv_n;
    // A tiny ridge keeps a constant stretch (singular moments) solvable.
    const double ridge = 1e-12 * (a + c) + 1e-300;
    const double ar = a + ridge, cr = c + ridge;
    const double det = ar * cr - b * b;
    const double explained = det > 0.0 ? (cr * b1 * b1 - 2.0 * b * b1 * b2 + ar * b2 * b2) / det : 0.0;
    return std::max(yy - explained, variance_floor_ * n);
  }

 private:
  std::vector<Sums> prefix_;
  double variance_floor_ = 0.0;
};

ArRowSums::Sums Add(const ArRowSums::Sums& x, const ArRowSums::Sums& y) {
  ArRowSums::Sums s;
  for (int q = 0; q < kSums; ++q) s[q] = x[q] + y[q];
  return s;
}

// Candidate splits k of [a, b): both sides at least min_piece_mm (measured
// between the pair positions that bound them: s[k] - s[a] on the left,
// s[b-1] - s[k-1] on the right) and min_piece_pairs long.
bool SplitAllowed(std::span<const double> s, const ChangePointOptions& o, int a, int k, int b) {
  return k - a >= o.min_piece_pairs && b - k >= o.min_piece_pairs && s[k] - s[a] >= o.min_piece_mm &&
         s[b - 1] - s[k - 1] >= o.min_piece_mm;
}

struct Split {
  int index = -1;        // -1: no split allowed
  int candidates = 0;
  double ratio = 0.0;    // LR at index
};

double LikelihoodRatio(const ArRowSums& sums, int a, int k, int b) {
  const ArRowSums::Sums left = sums.Rows(a, k), right = sums.Rows(k, b);
  const double n1 = left[0], n2 = right[0], n = n1 + n2;
  return n * std::log(sums.Rss(Add(left, right)) / n) - n1 * std::log(sums.Rss(left) / n1) -
         n2 * std::log(sums.Rss(right) / n2);
}

// Candidates are scanned every kCoarseStride, then every one within
// kCoarseStride of the best: the ratio is flat over the ~3 splits around a
// change (the rows next to a split belong to neither side) and smooth beyond,
// so the coarse scan lands on the peak's plateau at a third of the cost.
constexpr int kCoarseStride = 3;

Split BestSplit(const ArRowSums& sums, std::span<const double> s, const ChangePointOptions& o, int a, int b) {
  Split best;
  int first = -1;
  for (int k = a + 1; k < b; ++k) {
    if (!SplitAllowed(s, o, a, k, b)) continue;
    if (first < 0) first = k;
    ++best.candidates;
    if ((k - first) % kCoarseStride != 0) continue;
    const double ratio = LikelihoodRatio(sums, a, k, b);
    if (best.index < 0 || ratio > best.ratio) {
      best.index = k;
      best.ratio = ratio;
    }
  }
  if (best.index < 0) return best;
  const int coarse = best.index;
  for (int k = coarse - kCoarseStride + 1; k < coarse + kCoarseStride; ++k) {
    if (k == coarse || k <= a || k >= b || !SplitAllowed(s, o, a, k, b)) continue;
    const double ratio = LikelihoodRatio(sums, a, k, b);
    if (ratio > best.ratio) {
      best.index = k;
      best.ratio = ratio;
    }
  }
  return best;
}

// The AR(2) rows leave the two rows after a split out of both sides, so the
// likelihood ratio is nearly flat over k = c - 2 .. c for a change at c and
// the first maximum sits up to 2 pairs early. Re-place k within that
// ambiguity by a step in mean and variance of the values themselves, fitted
// over a local stretch (kLocalPairs each side, inside [a, b)).
constexpr int kLocalPairs = 15;
constexpr int kLocalShift = kLags + 1;

int RefineSplit(std::span<const double> x, int a, int k, int b) {
  const int lo = std::max(a, k - kLocalPairs), hi = std::min(b, k + kLocalPairs);
  double mean_square = 0.0;
  for (int i = lo; i < hi; ++i) mean_square += x[i] * x[i];
  const double floor = 1e-20 * mean_square / std::max(1, hi - lo) + 1e-300;
  auto cost = [&](int from, int to) {
    const int n = to - from;
    double m = 0.0;
    for (int i = from; i < to; ++i) m += x[i];
    m /= n;
    double v = 0.0;
    for (int i = from; i < to; ++i) v += (x[i] - m) * (x[i] - m);
    return n * std::log(std::max(v / n, floor));
  };
  int best = k;
  double best_cost = cost(lo, k) + cost(k, hi);
  for (int j = std::max(lo + 2, k - kLocalShift); j <= std::min(hi - 2, k + kLocalShift); ++j) {
    const double c = cost(lo, j) + cost(j, hi);
    if (c < best_cost) {
      best = j;
      best_cost = c;
    }
  }
  return best;
}

// c with P(chi-square(4) > c) = tail: the survival function is
// exp(-c/2) (1 + c/2); Newton on its logarithm from a start above the root.
double ChiSquare4UpperQuantile(double tail) {
  double c = std::max(1.0, -2.0 * std::log(tail) + 2.0 * std::log(-std::log(tail) + 1.0) + 2.0);
  for (int i = 0; i < 50; ++i) {
    const double f = -0.5 * c + std::log1p(0.5 * c) - std::log(tail);
    const double df = -0.5 + 0.5 / (1.0 + 0.5 * c);
    const double step = f / df;
    c -= step;
    if (std::abs(step) < 1e-12 * c) break;
  }
  return c;
}

}  // namespace

bool ChangePointOptions::IsValid(std::string* why) const {
  auto fail = [why](std::string message) {
    if (why != nullptr) *why = std::move(message);
    return false;
  };
  if (!(false_alarm_probability > 0.0 && false_alarm_probability < 1.0)) {
    return fail(absl::StrCat("false_alarm_probability ", false_alarm_probability, " must be in (0, 1)"));
  }
  if (!(std::isfinite(min_piece_mm) && min_piece_mm >= 0.0)) {
    return fail(absl::StrCat("min_piece_mm ", min_piece_mm, " must be a finite length >= 0"));
  }
  if (min_piece_pairs < 3 * kParameters) {
    return fail(absl::StrCat("min_piece_pairs ", min_piece_pairs, " must be >= ", 3 * kParameters,
                             " (3 rows per parameter of the AR(2) fit)"));
  }
  return true;
}

absl::StatusOr<std::vector<ChangePoint>> DetectChangePoints(std::span<const double> s_mm,
                                                            std::span<const double> values,
                                                            const ChangePointOptions& options) {
  std::string why;
  if (!options.IsValid(&why)) return absl::InvalidArgumentError(absl::StrCat("ChangePointOptions: ", why));
  if (s_mm.size() != values.size()) {
    return absl::InvalidArgumentError(absl::StrCat("change points: ", s_mm.size(), " positions but ",
                                                   values.size(), " values"));
  }
  const int n = static_cast<int>(values.size());
  for (int i = 0; i < n; ++i) {
    if (!std::isfinite(values[i]) || !std::isfinite(s_mm[i])) {
      return absl::InvalidArgumentError(absl::StrCat("change points: element ", i, " is not finite (s ", s_mm[i],
                                                     " mm, value ", values[i], ")"));
    }
    if (i > 0 && s_mm[i] < s_mm[i - 1]) {
      return absl::InvalidArgumentError(absl::StrCat("change points: position ", i, " (", s_mm[i],
                                                     " mm) is before position ", i - 1, " (", s_mm[i - 1], " mm)"));
    }
  }
  std::vector<ChangePoint> changes;
  const ArRowSums sums(values);

  std::vector<std::pair<int, int>> stack = {{0, n}};
  while (!stack.empty()) {
    const auto [a, b] = stack.back();
    stack.pop_back();
    const Split split = BestSplit(sums, s_mm, options, a, b);
    if (split.index < 0) continue;
    const double critical = ChiSquare4UpperQuantile(options.false_alarm_probability / split.candidates);
    if (!(split.ratio > critical)) continue;
    const int k = RefineSplit(values, a, split.index, b);
    changes.push_back({k, 0.5 * (s_mm[k - 1] + s_mm[k]), split.ratio, critical});
    stack.push_back({k + kChangeGuardPairs, b});
    stack.push_back({a, k - kChangeGuardPairs});
  }
  std::sort(changes.begin(), changes.end(), [](const ChangePoint& x, const ChangePoint& y) { return x.index < y.index; });

  // Re-place each change within the stretch between its neighbours: a split
  // found in a longer stretch (with another change inside) is pulled towards it.
  for (std::size_t i = 0; i < changes.size(); ++i) {
    const int a = i == 0 ? 0 : changes[i - 1].index + kChangeGuardPairs;
    const int b = i + 1 == changes.size() ? n : changes[i + 1].index - kChangeGuardPairs;
    const int found = BestSplit(sums, s_mm, options, a, b).index;
    const int k = found >= 0 ? RefineSplit(values, a, found, b) : -1;
    if (k >= 0) {
      changes[i].index = k;
      changes[i].s_mm = 0.5 * (s_mm[k - 1] + s_mm[k]);
    }
  }
  return changes;
}

}  // namespace surfmap
