#include "server/estimate/change_points.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <utility>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"
#include "server/estimate/normal_quantile.h"

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
    mean_ = mean;
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

  // The least-squares fit on `s`: with the intercept eliminated, the lag
  // coefficients solve Szz a = b over the centred moments, a 2 x 2 solve in
  // closed form, and RSS = Syy - a' b (floored). This runs ~3 times per
  // candidate split.
  struct Fit {
    double a1 = 0.0, a2 = 0.0, rss = 0.0;
  };
  Fit Solve(const Sums& s) const {
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
    Fit f;
    if (det > 0.0) {
      f.a1 = (cr * b1 - b * b2) / det;
      f.a2 = (ar * b2 - b * b1) / det;
    }
    f.rss = std::max(yy - (f.a1 * b1 + f.a2 * b2), variance_floor_ * n);
    return f;
  }
  double Rss(const Sums& s) const { return Solve(s).rss; }
  // The mean the rows are centred on.
  double mean() const { return mean_; }

 private:
  std::vector<Sums> prefix_;
  double mean_ = 0.0;
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

// How many values at the start of [a, b) the split test cannot split off:
// the first k - a with k an allowed left side (SplitAllowed's left rule).
int UnsplittableStart(std::span<const double> s, const ChangePointOptions& o, int a, int b) {
  int k = a + 1;
  while (k < b && !(k - a >= o.min_piece_pairs && s[k] - s[a] >= o.min_piece_mm)) ++k;
  return k - a;
}

int UnsplittableEnd(std::span<const double> s, const ChangePointOptions& o, int a, int b) {
  int k = b - 1;
  while (k > a && !(b - k >= o.min_piece_pairs && s[b - 1] - s[k - 1] >= o.min_piece_mm)) --k;
  return b - k;
}

// A band narrower than the stretch: [k1, k2) of one material inside [a, b)
// of another (a drag across a strip). Binary segmentation's single split sees
// it diluted: either side of any one split holds both materials, and a 7 mm
// rubber strip inside masonite was found in ~1 of 4 drags (its edge alone, in
// every one). The alternative "one model outside, another inside" is tested
// directly: LR as above with the outside's rows (both stretches, no lag
// reaching across k1 or k2) fitted together, so still 4 parameters more than
// the null, over every allowed (k1, k2): each of the three pieces at least the
// minimum. Scanned every kBandStride in both, then every pair within
// kBandStride of the best.
// Measured at a 45 mm drag (fit_trace_benchmark): stride 3 fits in 4.3x the
// time of binary segmentation alone, stride 6 in 1.9x and finds the same
// strips (0.868 against 0.8675 in change_points_rates_benchmark); 3 is what
// the maps were measured with through the service.
constexpr int kBandStride = kCoarseStride;

// The widest band tested, in pairs (51 mm at the paper's 0.1 mm): three
// times a 20 mm drag's window, so a plan's drags are tested for every band.
// A band wider than that holds enough pairs for a single split at its edge to
// find it, and the bound keeps the scan O(n) for a drag of any length (a
// trace of the server's 1,000,000 samples would otherwise take hours).
constexpr int kMaxBandPairs = 512;

struct BandSplit {
  int first = -1;  // -1: no band allowed
  int second = -1;
  std::int64_t candidates = 0;
  double ratio = 0.0;
};

double BandLikelihoodRatio(const ArRowSums& sums, int a, int k1, int k2, int b) {
  const ArRowSums::Sums outside = Add(sums.Rows(a, k1), sums.Rows(k2, b)), inside = sums.Rows(k1, k2);
  const double n1 = outside[0], n2 = inside[0], n = n1 + n2;
  return n * std::log(sums.Rss(Add(outside, inside)) / n) - n1 * std::log(sums.Rss(outside) / n1) -
         n2 * std::log(sums.Rss(inside) / n2);
}

bool BandAllowed(std::span<const double> s, const ChangePointOptions& o, int a, int k1, int k2, int b) {
  return SplitAllowed(s, o, a, k1, k2) && SplitAllowed(s, o, k1, k2, b);
}

BandSplit BestBand(const ArRowSums& sums, std::span<const double> s, const ChangePointOptions& o, int a, int b) {
  BandSplit best;
  auto consider = [&](int k1, int k2) {
    const double ratio = BandLikelihoodRatio(sums, a, k1, k2, b);
    if (best.first < 0 || ratio > best.ratio) best = {k1, k2, best.candidates, ratio};
  };
  // For each k1 the allowed k2 are one interval: the inside's minimum is
  // met from some k2 on, which only moves forward as k1 does (positions do
  // not decrease), and the right side's from the same last k2 for every k1;
  // the band is at most kMaxBandPairs wide.
  const int high = b - UnsplittableEnd(s, o, a, b);
  int low = a + 1;
  for (int k1 = a + UnsplittableStart(s, o, a, b); k1 < b; ++k1) {
    low = std::max(low, k1 + 1);
    while (low <= high && !BandAllowed(s, o, a, k1, low, b)) ++low;
    if (low > high) break;
    const int last = std::min(high, k1 + kMaxBandPairs);
    if (low > last) continue;
    best.candidates += last - low + 1;
    if ((k1 - a) % kBandStride != 0) continue;
    for (int k2 = low; k2 <= last; k2 += kBandStride) consider(k1, k2);
  }
  if (best.first < 0) return best;
  const int c1 = best.first, c2 = best.second;
  for (int k1 = c1 - kBandStride + 1; k1 < c1 + kBandStride; ++k1) {
    for (int k2 = c2 - kBandStride + 1; k2 < c2 + kBandStride; ++k2) {
      if ((k1 == c1 && k2 == c2) || k1 <= a || k2 >= b || k2 <= k1 || k2 - k1 > kMaxBandPairs ||
          !BandAllowed(s, o, a, k1, k2, b)) {
        continue;
      }
      consider(k1, k2);
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

// x_t = c + a1 x_(t-1) + a2 x_(t-2) + e_t, least squares over rows t in
// [2, n) of `x`; sigma the residuals' standard deviation (3 parameters).
struct Ar2Model {
  double c = 0.0, a1 = 0.0, a2 = 0.0, sigma = 0.0;
};

Ar2Model FitAr2(std::span<const double> x) {
  const ArRowSums sums(x);
  const ArRowSums::Sums r = sums.Rows(0, static_cast<int>(x.size()));
  const double n = r[0];
  const ArRowSums::Fit fit = sums.Solve(r);
  Ar2Model m;
  m.a1 = fit.a1;
  m.a2 = fit.a2;
  // Intercept in the original units (the sums are centred on the mean): the
  // mean of y minus the lags' contribution.
  const double mean = sums.mean();
  m.c = (r[6] / n + mean) - m.a1 * (r[1] / n + mean) - m.a2 * (r[2] / n + mean);
  m.sigma = std::sqrt(fit.rss / std::max(1.0, n - 3.0));
  return m;
}

// The end of a stretch: its last `tested` values may be another material,
// too few for the AR(2) split test. The rest's model predicts each of them
// from the two before; at a change the first value of the other material is
// far from its prediction (the jump), and the values after it sit on the
// other side of the rest's mean. Returns the index (into `x`) of that first
// value when its standardised residual exceeds `z_critical` and the mean of
// the values after it moved the same way by at least half the residual (after
// a lone spike they do not), leaving at least `min_end` values; index -1
// otherwise. `z` is that residual's standardised size.
struct EndSplit {
  int index = -1;
  double z = 0.0;
};

EndSplit EndChange(std::span<const double> x, int tested, int min_end, double z_critical) {
  const int n = static_cast<int>(x.size());
  const int rest = n - tested;
  if (rest < 3 * kParameters || tested < min_end) return {};
  const Ar2Model m = FitAr2(x.first(rest));
  if (!(m.sigma > 0.0)) return {};
  int best = -1;
  double best_z = 0.0, best_residual = 0.0;
  for (int t = rest; t <= n - min_end; ++t) {
    const double residual = x[t] - (m.c + m.a1 * x[t - 1] + m.a2 * x[t - 2]);
    const double z = std::abs(residual) / m.sigma;
    if (z > best_z) best = t, best_z = z, best_residual = residual;
  }
  if (best < 0 || !(best_z > z_critical)) return {};
  // The values after the candidate (not it: a spike is one value).
  double rest_mean = 0.0, end_mean = 0.0;
  for (int t = 0; t < rest; ++t) rest_mean += x[t];
  for (int t = best + 1; t < n; ++t) end_mean += x[t];
  rest_mean /= rest;
  end_mean /= n - best - 1;
  const double shift = end_mean - rest_mean;
  if (!(shift * best_residual > 0.0 && std::abs(shift) >= 0.5 * std::abs(best_residual))) return {};
  return {best, best_z};
}

// The change before element k, midway between it and the one before.
ChangePoint ChangeAt(std::span<const double> s_mm, int k, double statistic, double critical_value) {
  return {k, 0.5 * (s_mm[k - 1] + s_mm[k]), statistic, critical_value};
}

// Binary segmentation of [a, b) (the method above), each change re-placed
// within the stretch between its neighbours at the end.
std::vector<ChangePoint> Segment(const ArRowSums& sums, std::span<const double> s_mm, std::span<const double> values,
                                 const ChangePointOptions& options, int a0, int b0) {
  std::vector<ChangePoint> changes;
  std::vector<std::pair<int, int>> stack = {{a0, b0}};
  while (!stack.empty()) {
    const auto [a, b] = stack.back();
    stack.pop_back();
    const Split split = BestSplit(sums, s_mm, options, a, b);
    if (split.index < 0) continue;
    const double critical = ChiSquare4UpperQuantile(options.false_alarm_probability / split.candidates);
    if (!(split.ratio > critical)) {
      // No one split: a band inside the stretch, tested on its own at the
      // same false-alarm probability over its own candidates.
      const BandSplit band = BestBand(sums, s_mm, options, a, b);
      if (band.first < 0) continue;
      const double band_critical = ChiSquare4UpperQuantile(options.false_alarm_probability / band.candidates);
      if (!(band.ratio > band_critical)) continue;
      const int k1 = RefineSplit(values, a, band.first, band.second);
      const int k2 = RefineSplit(values, band.first, band.second, b);
      changes.push_back(ChangeAt(s_mm, k1, band.ratio, band_critical));
      changes.push_back(ChangeAt(s_mm, k2, band.ratio, band_critical));
      stack.push_back({k2 + kChangeGuardPairs, b});
      stack.push_back({k1 + kChangeGuardPairs, k2 - kChangeGuardPairs});
      stack.push_back({a, k1 - kChangeGuardPairs});
      continue;
    }
    const int k = RefineSplit(values, a, split.index, b);
    changes.push_back(ChangeAt(s_mm, k, split.ratio, critical));
    stack.push_back({k + kChangeGuardPairs, b});
    stack.push_back({a, k - kChangeGuardPairs});
  }
  std::sort(changes.begin(), changes.end(), [](const ChangePoint& x, const ChangePoint& y) { return x.index < y.index; });

  // Re-place each change within the stretch between its neighbours: a split
  // found in a longer stretch (with another change inside) is pulled towards it.
  for (std::size_t i = 0; i < changes.size(); ++i) {
    const int a = i == 0 ? a0 : changes[i - 1].index + kChangeGuardPairs;
    const int b = i + 1 == changes.size() ? b0 : changes[i + 1].index - kChangeGuardPairs;
    const int found = BestSplit(sums, s_mm, options, a, b).index;
    const int k = found >= 0 ? RefineSplit(values, a, found, b) : -1;
    if (k >= 0) {
      changes[i].index = k;
      changes[i].s_mm = 0.5 * (s_mm[k - 1] + s_mm[k]);
    }
  }
  return changes;
}

// Ends of a series split off by EndChange: the start from the stretch
// [0, first_end) (fitted backwards), the end from [last_start, n); index
// -1 where none. `index` is the change's (the first value after it).
struct EndSplits {
  EndSplit start, end;
  double z_critical = 0.0;
  bool any() const { return start.index >= 0 || end.index >= 0; }
};

EndSplits FindEnds(std::span<const double> values, std::span<const double> s_mm, const ChangePointOptions& options,
                   int first_end, int last_start) {
  const int n = static_cast<int>(values.size());
  const int head = UnsplittableStart(s_mm, options, 0, first_end);
  const int tail = UnsplittableEnd(s_mm, options, last_start, n);
  EndSplits out;
  // Half the false-alarm probability per look (DetectChangePoints looks
  // twice), over the values tested, two-sided: P(|Z| > z) = alpha / 2 /
  // tested, so P(Z > z) is half that.
  out.z_critical = NormalUpperQuantile(0.25 * options.false_alarm_probability / std::max(1, head + tail));
  // An end keeps at least 2 pairs beside the transitional pair.
  constexpr int kMinEnd = 2 + kChangeGuardPairs;
  std::vector<double> reversed(values.begin(), values.begin() + first_end);
  std::reverse(reversed.begin(), reversed.end());
  const EndSplit start = EndChange(reversed, head, kMinEnd, out.z_critical);
  // reversed[e] is values[first_end - 1 - e], the last value of the other
  // material; the change comes after it.
  if (start.index >= 0) out.start = {first_end - start.index, start.z};
  const EndSplit end = EndChange(values.subspan(last_start, n - last_start), tail, kMinEnd, out.z_critical);
  if (end.index >= 0) out.end = {last_start + end.index, end.z};
  // Both ends of a short series may claim overlapping values: keep the
  // clearer one.
  if (out.start.index >= 0 && out.end.index >= 0 && out.end.index - out.start.index < 3 * kParameters) {
    (out.start.z >= out.end.z ? out.end : out.start) = EndSplit{};
  }
  return out;
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
  if (!(std::isfinite(group_spacing_mm) && group_spacing_mm >= 0.0)) {
    return fail(absl::StrCat("group_spacing_mm ", group_spacing_mm, " must be a finite length >= 0"));
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
  // The drag's ends first, with the whole series as the rest (interior
  // changes only widen its fit's residuals: fewer ends split, never more);
  // then, where none was split, the stretches before the first change and
  // after the last that segmentation found. Each look spends half the
  // false-alarm probability.
  EndSplits ends = FindEnds(values, s_mm, options, n, 0);
  if (!ends.any()) {
    std::vector<ChangePoint> changes = Segment(ArRowSums(values), s_mm, values, options, 0, n);
    if (changes.empty()) return changes;  // its ends were the whole series': tested
    ends = FindEnds(values, s_mm, options, changes.front().index - kChangeGuardPairs,
                    changes.back().index + kChangeGuardPairs);
    if (!ends.any()) return changes;
  }
  // The stretch without its ends, searched again.
  const int a = ends.start.index < 0 ? 0 : ends.start.index + kChangeGuardPairs;
  const int b = ends.end.index < 0 ? n : ends.end.index - kChangeGuardPairs;
  std::vector<ChangePoint> changes;
  auto end_point = [&](const EndSplit& e) {
    const int k = e.index;
    return ChangeAt(s_mm, k, e.z * e.z, ends.z_critical * ends.z_critical);
  };
  if (ends.start.index >= 0) changes.push_back(end_point(ends.start));
  if (b - a > 0) {
    for (ChangePoint c : Segment(ArRowSums(values.subspan(a, b - a)), s_mm.subspan(a, b - a),
                                 values.subspan(a, b - a), options, 0, b - a)) {
      c.index += a;
      changes.push_back(c);
    }
  }
  if (ends.end.index >= 0) changes.push_back(end_point(ends.end));
  return changes;
}

}  // namespace surfmap
