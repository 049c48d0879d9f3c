#include "server/estimate/force_variation.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "absl/strings/str_format.h"
#include "server/estimate/linear_detrend.h"

namespace surfmap {

std::vector<double> ReadAtStep(const std::vector<double>& pos, const std::vector<double>& val, double start,
                               double end, double step, bool follow_samples) {
  const int nv = static_cast<int>(pos.size());
  std::vector<double> out;
  // A step that is not positive, or a grid past the series' limit, reads
  // nothing (ForceVariationSeries refuses them first, naming them).
  const double points = (end - start) / step;
  if (nv == 0 || !(step > 0.0) || !(points >= 0.0) || points >= kMaxRoughnessGridPoints) return out;
  MonotoneBracket bracket(nv);
  const auto pos_key = [&](int i) { return pos[i]; };
  const auto nearest = [&](double at) {
    int k;
    double w;
    bracket.Locate(at, pos_key, &k, &w);
    return w < 0.5 ? k : std::min(k + 1, nv - 1);
  };
  if (!follow_samples) {
    // Nearest sample, not linear interpolation: the probe samples about
    // every grid step, and interpolating between neighbours at a fractional
    // offset would low-pass the texture (a1 of rubber 0.6 read as ~1.2).
    const int grid = static_cast<int>(std::floor(points + 1e-9)) + 1;
    out.reserve(grid);
    for (int g = 0; g < grid; ++g) out.push_back(val[nearest(start + g * step)]);
    return out;
  }
  // From the sample nearest the start, each next one is the later sample
  // nearest one step on; the series ends with the last within half a step
  // of the end.
  int current = nearest(start);
  out.push_back(val[current]);
  for (;;) {
    const double target = pos[current] + step;
    int next = current + 1;
    if (next >= nv) break;
    while (next + 1 < nv && std::abs(pos[next + 1] - target) <= std::abs(pos[next] - target)) ++next;
    if (pos[next] > end + 0.5 * step) break;
    out.push_back(val[next]);
    current = next;
  }
  return out;
}

namespace {

// Variation of one pass read at the step (ReadAtStep), detrended.
// `index(m)` lists the pass's sample indices in increasing arc length.
template <typename IndexFn>
Eigen::VectorXd ResamplePass(std::span<const DragSample> samples, const std::vector<double>& s, int count,
                             const IndexFn& index, const FrictionFit& friction,
                             const std::vector<Eigen::Vector3d>& normals, double mu, double start, double end,
                             double step, bool follow_samples, std::vector<double>& pos, std::vector<double>& val) {
  pos.clear();
  val.clear();
  const int np = friction.n_pairs;
  const auto pair_key = [&](int i) { return friction.pair_s_mm[i]; };
  MonotoneBracket normal_bracket(np);
  for (int m = 0; m < count; ++m) {
    const int i = index(m);
    // One sample beyond each end of the window, so the nearest to each end is among them.
    const bool before = m + 1 < count && s[index(m + 1)] < start;
    const bool after = m > 0 && s[index(m - 1)] > end;
    if (before || after) continue;
    int k;
    double w;
    normal_bracket.Locate(s[i], pair_key, &k, &w);
    const int k1 = std::min(k + 1, np - 1);
    // With m = `normal`, interpolated and not unit: fn = f.m / |m| and
    // ft^2 = |f|^2 - fn^2. Two independent square roots and a division,
    // instead of normalising m and then measuring f - fn n (a dependent chain).
    const Eigen::Vector3d normal = (1.0 - w) * normals[k] + w * normals[k1];
    const Eigen::Vector3d& f = samples[i].force;
    const double m_norm = normal.norm();
    const double fm = f.dot(normal);
    const double fn = fm / m_norm;
    const double ft = std::sqrt(std::max(0.0, f.squaredNorm() - fm * fm / (m_norm * m_norm)));
    pos.push_back(s[i]);
    val.push_back(ft - mu * fn);
  }
  const std::vector<double> read = ReadAtStep(pos, val, start, end, step, follow_samples);
  Eigen::VectorXd out = Eigen::Map<const Eigen::VectorXd>(read.data(), static_cast<Eigen::Index>(read.size()));
  RemoveLinearTrend(out.data(), static_cast<int>(out.size()));
  return out;
}

}  // namespace

bool SeriesOptions::IsValid(std::string* why) const {
  if (!(halfwidth_mm >= 0.0 && halfwidth_mm <= 10.0)) {
    *why = "series normal halfwidth_mm must be in 0..10";
    return false;
  }
  if (!(max_turn_deg > 0.0 && max_turn_deg <= 90.0)) {
    *why = "series normal max_turn_deg must be in (0, 90]";
    return false;
  }
  return true;
}

std::vector<Eigen::Vector3d> SeriesNormals(const FrictionFit& friction, const SeriesOptions& options) {
  const int n = friction.n_pairs;
  const std::vector<double>& s = friction.pair_s_mm;
  const std::vector<Eigen::Vector3d>& own = friction.pair_normal;
  if (!(options.halfwidth_mm > 0.0)) return own;
  const double min_cos = std::cos(options.max_turn_deg * std::numbers::pi / 180.0);
  std::vector<Eigen::Vector3d> out(n);
  int lo = 0, hi = 0;  // pairs lo..hi-1 lie within the widest reach of pair i
  for (int i = 0; i < n; ++i) {
    const double h = std::min({options.halfwidth_mm, s[i] - s[0], s[n - 1] - s[i]});
    while (s[lo] < s[i] - options.halfwidth_mm) ++lo;
    while (hi < n && s[hi] <= s[i] + options.halfwidth_mm) ++hi;
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (int j = lo; j < hi; ++j) {
      if (std::abs(s[j] - s[i]) <= h && own[j].dot(own[i]) >= min_cos) sum += own[j];
    }
    out[i] = sum.normalized();  // pair i itself is always in the sum
  }
  return out;
}

absl::StatusOr<std::vector<Eigen::VectorXd>> ForceVariationSeries(std::span<const DragSample> forward,
                                                     std::span<const DragSample> reverse,
                                                     const PathPairing& pairing,
                                                     const FrictionFit& friction, double step_mm,
                                                     const SeriesOptions& series) {
  return ForceVariationSeries(forward, reverse, pairing, friction, friction.window_start_mm,
                              friction.window_end_mm, friction.mu, step_mm, series);
}

absl::StatusOr<std::vector<Eigen::VectorXd>> ForceVariationSeries(std::span<const DragSample> forward,
                                                     std::span<const DragSample> reverse,
                                                     const PathPairing& pairing,
                                                     const FrictionFit& friction, double start_mm,
                                                     double end_mm, double mu, double step_mm,
                                                     const SeriesOptions& series) {
  const double start = start_mm;
  const double length = end_mm - start;
  // Counted in double: the cast to int and the two series' allocation come
  // only after the count is known to be in range.
  const double points = std::floor(length / step_mm + 1e-9) + 1.0;
  if (!(step_mm > 0.0) || !(points >= 2.0) || friction.n_pairs < 1) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "data window %.3f..%.3f mm holds fewer than 2 points of the %.3g mm roughness grid",
        start, end_mm, step_mm));
  }
  if (points > kMaxRoughnessGridPoints) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "data window %.6g..%.6g mm holds %.4g points of the %.3g mm roughness grid; the limit is %d",
        start, end_mm, points, step_mm, kMaxRoughnessGridPoints));
  }
  const int nf = static_cast<int>(forward.size());
  const int nr = static_cast<int>(reverse.size());
  std::vector<double> pos, val;
  pos.reserve(std::max(nf, nr));
  val.reserve(std::max(nf, nr));
  const std::vector<Eigen::Vector3d> normals = SeriesNormals(friction, series);
  std::vector<Eigen::VectorXd> out;
  out.push_back(ResamplePass(forward, pairing.forward_s, nf, [](int m) { return m; }, friction, normals, mu, start,
                             end_mm, step_mm, series.follow_samples, pos, val));
  out.push_back(ResamplePass(reverse, pairing.reverse_s, nr, [nr](int m) { return nr - 1 - m; }, friction, normals,
                             mu, start, end_mm, step_mm, series.follow_samples, pos, val));
  for (int pass = 0; pass < 2; ++pass) {
    if (out[pass].size() < 2) {
      return absl::InvalidArgumentError(absl::StrFormat(
          "the %s pass holds %d sample(s) in %.3f..%.3f mm; a roughness series needs 2", pass == 0 ? "forward" : "reverse",
          static_cast<int>(out[pass].size()), start, end_mm));
    }
  }
  return out;
}

double PauseNoiseStd(std::span<const DragSample> pause) {
  const int n = static_cast<int>(pause.size());
  if (n < 3) return 0.0;
  // var(f[i+1] - f[i]) = 2 var(noise) for white noise; a slow trend adds
  // only its squared increment.
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (int i = 1; i < n; ++i) mean += pause[i].force - pause[i - 1].force;
  mean /= n - 1;
  double ss = 0.0;
  for (int i = 1; i < n; ++i) ss += (pause[i].force - pause[i - 1].force - mean).squaredNorm();
  const double per_axis_variance = ss / (3.0 * (n - 2)) / 2.0;
  return std::sqrt(per_axis_variance);
}

}  // namespace surfmap
