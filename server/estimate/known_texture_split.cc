#include "server/estimate/known_texture_split.h"

#include <cmath>
#include <limits>
#include <numbers>
#include <vector>

#include <Eigen/Dense>
#include "absl/strings/str_cat.h"

namespace surfmap {
namespace {

// log p_t(x_i | x_(i-1), x_(i-2)) for a row i >= 2.
double RowLogDensity(std::span<const double> x, int i, const SeriesTexture& t, double log_norm) {
  const double e = (x[i] - t.mean) - t.a1 * (x[i - 1] - t.mean) - t.a2 * (x[i - 2] - t.mean);
  return log_norm - 0.5 * e * e / t.innovation_variance;
}

double LogNorm(const SeriesTexture& t) { return -0.5 * std::log(2.0 * std::numbers::pi * t.innovation_variance); }

// rows[m][i]: sum of log p_m(x_j | x_(j-1), x_(j-2)) over rows j < i (rows
// start at 2).
std::vector<std::vector<double>> RowPrefixSums(std::span<const double> x, const std::vector<SeriesTexture>& textures) {
  const int n = static_cast<int>(x.size());
  std::vector<std::vector<double>> sums(textures.size(), std::vector<double>(n + 1, 0.0));
  for (std::size_t m = 0; m < textures.size(); ++m) {
    const double log_norm = LogNorm(textures[m]);
    for (int i = 0; i < n; ++i) {
      sums[m][i + 1] = sums[m][i] + (i >= 2 ? RowLogDensity(x, i, textures[m], log_norm) : 0.0);
    }
  }
  return sums;
}

struct Search {
  std::span<const double> s;
  const std::vector<std::vector<double>>& sums;
  const KnownTextureSplitOptions& options;
  std::vector<ChangePoint>& out;

  // Sum of texture m's rows in [from, to).
  double Rows(int m, int from, int to) const { return to > from ? sums[m][to] - sums[m][from] : 0.0; }

  // log(K / alpha) for K = `candidates` splits (or bands) x the ordered
  // pairs of different textures: the Markov and union bound (header).
  double CriticalValue(long long candidates) const {
    const int textures = static_cast<int>(sums.size());
    return std::log(static_cast<double>(candidates) * textures * (textures - 1) / options.false_alarm_probability);
  }

  // A change before pair k, found with `statistic` above `critical`.
  void AddChange(int k, double statistic, double critical) {
    ChangePoint change;
    change.index = k;
    change.s_mm = 0.5 * (s[k - 1] + s[k]);
    change.statistic = statistic;
    change.critical_value = critical;
    out.push_back(change);
  }

  bool SideLongEnough(int first, int last) const {  // pairs first..last inclusive
    return last - first + 1 >= options.min_piece_pairs && s[last] - s[first] >= options.min_piece_mm;
  }

  // Searches [a, b) and, where a change is kept, both sides again.
  void Segment(int a, int b) {
    const int textures = static_cast<int>(sums.size());
    int candidates = 0;
    double best = -std::numeric_limits<double>::infinity();
    int best_k = -1;
    for (int k = a + 1; k < b; ++k) {
      // Left pairs a..k-2, right k+1..b-1 (pairs k-1 and k are transitional).
      if (!SideLongEnough(a, k - 2) || !SideLongEnough(k + 1, b - 1)) continue;
      ++candidates;
      const int left_from = a + 2, left_to = k - 1, right_from = k + 3, right_to = b;
      double single = -std::numeric_limits<double>::infinity();
      for (int m = 0; m < textures; ++m) {
        single = std::max(single, Rows(m, left_from, left_to) + Rows(m, right_from, right_to));
      }
      for (int l = 0; l < textures; ++l) {
        for (int r = 0; r < textures; ++r) {
          if (l == r) continue;
          const double llr = Rows(l, left_from, left_to) + Rows(r, right_from, right_to) - single;
          if (llr > best) best = llr, best_k = k;
        }
      }
    }
    if (candidates == 0) return;
    const double critical = CriticalValue(candidates);
    if (!(best > critical)) {
      if (options.test_bands) SegmentBand(a, b);
      return;
    }
    Segment(a, best_k - 1);
    AddChange(best_k, best, critical);
    Segment(best_k + 1, b);
  }

  // Where no single split is kept: one texture on a band [k1, k2) and
  // another on the rest of [a, b), each of the three parts long enough
  // (the header says why). The same Markov and union bound over every
  // (k1, k2, outer texture, band texture) tried.
  void SegmentBand(int a, int b) {
    const int textures = static_cast<int>(sums.size());
    long long candidates = 0;
    double best = -std::numeric_limits<double>::infinity();
    int best_k1 = -1, best_k2 = -1;
    std::vector<double> band(textures), outer(textures);
    for (int k1 = a + 1; k1 < b; ++k1) {
      if (!SideLongEnough(a, k1 - 2)) continue;
      for (int k2 = k1 + 1; k2 < b; ++k2) {
        // Pairs k1-1, k1, k2-1 and k2 are transitional.
        if (!SideLongEnough(k1 + 1, k2 - 2)) continue;
        if (!SideLongEnough(k2 + 1, b - 1)) break;
        ++candidates;
        double single = -std::numeric_limits<double>::infinity();
        for (int m = 0; m < textures; ++m) {
          band[m] = Rows(m, k1 + 3, k2 - 1);
          outer[m] = Rows(m, a + 2, k1 - 1) + Rows(m, k2 + 3, b);
          single = std::max(single, band[m] + outer[m]);
        }
        for (int o = 0; o < textures; ++o) {
          for (int m = 0; m < textures; ++m) {
            if (o == m) continue;
            const double llr = outer[o] + band[m] - single;
            if (llr > best) best = llr, best_k1 = k1, best_k2 = k2;
          }
        }
      }
    }
    if (candidates == 0) return;
    const double critical = CriticalValue(candidates);
    if (!(best > critical)) return;
    Segment(a, best_k1 - 1);
    AddChange(best_k1, best, critical);
    Segment(best_k1 + 1, best_k2 - 1);
    AddChange(best_k2, best, critical);
    Segment(best_k2 + 1, b);
  }
};

}  // namespace

bool KnownTextureSplitOptions::IsValid(std::string* why) const {
  auto fail = [why](const char* m) {
    if (why != nullptr) *why = m;
    return false;
  };
  if (!(false_alarm_probability > 0.0 && false_alarm_probability < 1.0)) {
    return fail("false_alarm_probability must be in (0, 1)");
  }
  if (!(std::isfinite(min_piece_mm) && min_piece_mm >= 0.0)) return fail("min_piece_mm must be >= 0");
  if (min_piece_pairs < 3) return fail("min_piece_pairs must be >= 3");
  return true;
}

absl::StatusOr<SeriesTexture> FitSeriesTexture(const std::vector<std::span<const double>>& stretches, int min_rows) {
  double total = 0.0;
  int values = 0;
  for (std::span<const double> x : stretches) {
    for (double v : x) {
      if (!std::isfinite(v)) return absl::InvalidArgumentError("series texture: a value is not finite");
      total += v;
      ++values;
    }
  }
  if (values == 0) return absl::InvalidArgumentError("series texture: no values");
  SeriesTexture t;
  t.mean = total / values;
  Eigen::Matrix2d normal = Eigen::Matrix2d::Zero();
  Eigen::Vector2d rhs = Eigen::Vector2d::Zero();
  int rows = 0;
  for (std::span<const double> x : stretches) {
    for (std::size_t i = 2; i < x.size(); ++i) {
      const Eigen::Vector2d lags(x[i - 1] - t.mean, x[i - 2] - t.mean);
      normal += lags * lags.transpose();
      rhs += lags * (x[i] - t.mean);
      ++rows;
    }
  }
  if (rows < min_rows) {
    return absl::InvalidArgumentError(absl::StrCat("series texture: ", rows, " rows, fewer than ", min_rows));
  }
  Eigen::LDLT<Eigen::Matrix2d> ldlt(normal);
  if (ldlt.info() != Eigen::Success || !(std::abs(normal.determinant()) > 1e-300)) {
    return absl::InvalidArgumentError("series texture: the lagged values are collinear");
  }
  const Eigen::Vector2d a = ldlt.solve(rhs);
  t.a1 = a(0);
  t.a2 = a(1);
  double rss = 0.0;
  for (std::span<const double> x : stretches) {
    for (std::size_t i = 2; i < x.size(); ++i) {
      const double e = (x[i] - t.mean) - t.a1 * (x[i - 1] - t.mean) - t.a2 * (x[i - 2] - t.mean);
      rss += e * e;
    }
  }
  t.innovation_variance = rss / std::max(1, rows - 2);
  if (!(t.innovation_variance > 0.0)) return absl::InvalidArgumentError("series texture: zero innovation variance");
  return t;
}

absl::StatusOr<std::vector<ChangePoint>> FindKnownTextureChanges(std::span<const double> mu,
                                                                        std::span<const double> s_mm,
                                                                        const std::vector<SeriesTexture>& textures,
                                                                        const KnownTextureSplitOptions& options) {
  std::string why;
  if (!options.IsValid(&why)) return absl::InvalidArgumentError(absl::StrCat("known texture split: ", why));
  if (mu.size() != s_mm.size()) {
    return absl::InvalidArgumentError(
        absl::StrCat("known texture split: ", mu.size(), " values but ", s_mm.size(), " positions"));
  }
  for (std::size_t m = 0; m < textures.size(); ++m) {
    if (!(textures[m].innovation_variance > 0.0) || !std::isfinite(textures[m].innovation_variance)) {
      return absl::InvalidArgumentError(absl::StrCat("known texture split: texture ", m, " has innovation variance ",
                                                     textures[m].innovation_variance));
    }
  }
  std::vector<ChangePoint> out;
  if (textures.size() < 2 || mu.size() < 4) return out;
  const std::vector<std::vector<double>> sums = RowPrefixSums(mu, textures);
  Search{s_mm, sums, options, out}.Segment(0, static_cast<int>(mu.size()));
  static_assert(kChangeGuardPairs == 1, "the rows left out next to a change assume one transitional pair a side");
  return out;
}

double SeriesLogLikelihood(std::span<const double> x, const SeriesTexture& texture) {
  const double log_norm = LogNorm(texture);
  double sum = 0.0;
  for (int i = 2; i < static_cast<int>(x.size()); ++i) sum += RowLogDensity(x, i, texture, log_norm);
  return sum;
}

}  // namespace surfmap
