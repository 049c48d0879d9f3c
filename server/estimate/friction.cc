#include "server/estimate/friction.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>
#include "absl/status/status.h"
#include "absl/strings/str_format.h"

namespace surfmap {
namespace {

// The shortest stretch of the forward pass whose ends give the direction of
// motion at a sample (for the sign of its friction): 20x a typical rig's
// 0.005 mm position noise. At 10 mm/s and 100 Hz the neighbours either side
// are 0.2 mm apart and are used, as always; at 1 kHz they are 0.02 mm apart,
// the noise of their difference (0.007 mm per axis) turned the direction
// round for ~1 pair in 400, and glass's pair then read -0.106 for 0.106.
constexpr double kMotionBaselineMm = 0.1;

// The widest search for that stretch, samples either side. The fastest rig
// accepted (100 kHz at 10 mm/s) reaches 0.1 mm in 50. The bound keeps the
// search linear in the pass whatever it holds: unbounded, a sample in a
// stretch where the probe barely moves scanned out to the pass's ends (the
// data window leaves long pauses out, so this is a guard, not a measured
// slowdown).
constexpr int kMaxMotionHalfWidth = 256;

// Forward sample i + h minus sample i - h (clamped to the pass), for the
// smallest h >= 1 whose ends lie kMotionBaselineMm apart, or the widest h
// searched (the probe barely moved there: whatever motion there is).
Eigen::Vector3d MotionAt(std::span<const DragSample> forward, int i) {
  const int n = static_cast<int>(forward.size());
  Eigen::Vector3d motion = Eigen::Vector3d::Zero();
  for (int h = 1; h <= kMaxMotionHalfWidth; ++h) {
    const int prev = std::max(0, i - h), next = std::min(n - 1, i + h);
    motion = forward[next].position - forward[prev].position;
    if (motion.squaredNorm() >= kMotionBaselineMm * kMotionBaselineMm || (prev == 0 && next == n - 1)) break;
  }
  return motion;
}

}  // namespace

bool FrictionOptions::IsValid(std::string* why) const {
  auto fail = [&](const char* message) {
    if (why) *why = message;
    return false;
  };
  if (!(min_contact_force_n > 0.0)) return fail("min_contact_force_n must be > 0");
  if (min_pairs < 2) return fail("min_pairs must be >= 2");
  return true;
}

absl::StatusOr<FrictionFit> FitFriction(std::span<const DragSample> forward,
                                        std::span<const DragSample> reverse,
                                        const PathPairing& pairing, const DataWindow& window,
                                        const FrictionOptions& options) {
  const int nf = static_cast<int>(forward.size());
  const int nr = static_cast<int>(reverse.size());
  const std::vector<double>& fs = pairing.forward_s;
  const std::vector<double>& rs = pairing.reverse_s;

  int first = 0;
  while (first < nf && fs[first] < window.start_mm) ++first;
  int last = first;
  while (last < nf && fs[last] <= window.end_mm) ++last;
  const int n = last - first;
  if (n < options.min_pairs) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "data window %.3f..%.3f mm holds %d forward sample(s); the friction fit needs at least %d",
        window.start_mm, window.end_mm, n, options.min_pairs));
  }

  FrictionFit fit;
  fit.window_start_mm = window.start_mm;
  fit.window_end_mm = window.end_mm;
  fit.first_forward_sample = first;
  fit.n_pairs = n;
  fit.pair_s_mm.reserve(n);
  fit.pair_mu.reserve(n);
  fit.pair_normal.reserve(n);

  // Reverse samples sorted by arc length = the reverse pass read backwards.
  const auto reverse_key = [&](int i) { return rs[nr - 1 - i]; };
  MonotoneBracket bracket(nr);
  const double min_force = options.min_contact_force_n;
  Eigen::Vector3d normal_sum = Eigen::Vector3d::Zero();
  // Per pair everything is kept in terms of the raw forces f and r: with
  // F = |f| and R = |r|, fh + rh is parallel to u = R f + F r, fh - rh to
  // d = R f - F r, and tan(theta/2) = |fh x rh| / (1 + fh . rh)
  // = |f x r| / (F R + f . r). F, R and |f x r| are independent square
  // roots, and mu costs one division: no chain of normalisations waiting on
  // each other (this loop is a sixth of a whole fit).
  const double min_force2 = min_force * min_force;
  for (int i = first; i < last; ++i) {
    const double s = fs[i];
    const Eigen::Vector3d& f = forward[i].force;
    const double f_norm2 = f.squaredNorm();
    if (!(f_norm2 >= min_force2)) {
      return absl::InvalidArgumentError(absl::StrFormat(
          "forward sample %d (t=%.3f s): contact force %.4g N is below %.3g N (probe not in "
          "contact?)",
          i, forward[i].t, std::sqrt(f_norm2), min_force));
    }
    int k;
    double w;
    bracket.Locate(s, reverse_key, &k, &w);
    const int a = nr - 1 - k, b = nr - 2 - k < 0 ? a : nr - 2 - k;  // reverse indices
    const Eigen::Vector3d r = (1.0 - w) * reverse[a].force + w * reverse[b].force;
    const double r_norm2 = r.squaredNorm();
    if (!(r_norm2 >= min_force2)) {
      return absl::InvalidArgumentError(absl::StrFormat(
          "reverse samples %d-%d (t=%.3f s): contact force %.4g N is below %.3g N (probe not in "
          "contact?)",
          std::min(a, b), std::max(a, b), reverse[a].t, std::sqrt(r_norm2), min_force));
    }
    const double f_norm = std::sqrt(f_norm2);
    const double r_norm = std::sqrt(r_norm2);
    const double cross_norm = f.cross(r).norm();
    const Eigen::Vector3d u = r_norm * f + f_norm * r;
    const double u_norm = u.norm();
    const double fr = f_norm * r_norm;
    if (!(u_norm > 1e-9 * fr)) {  // |fh + rh| <= 1e-9
      return absl::InvalidArgumentError(absl::StrFormat(
          "forward sample %d (s=%.3f mm): forward and reverse forces are opposite, no normal", i,
          s));
    }
    // tan(theta / 2) = sin(theta) / (1 + cos(theta)): the same value as
    // tan(atan2(|cross|, dot) / 2), as accurate at small angles (no acos),
    // without the two transcendental calls.
    double mu = cross_norm / (fr + f.dot(r));
    // Sign: forward friction points against the forward motion, so fh - rh
    // has a negative component along it; the opposite means negative friction.
    const Eigen::Vector3d motion = MotionAt(forward, i);
    if ((r_norm * f - f_norm * r).dot(motion) > 0.0) mu = -mu;
    const Eigen::Vector3d normal = u / u_norm;
    fit.pair_s_mm.push_back(s);
    fit.pair_mu.push_back(mu);
    fit.pair_normal.push_back(normal);
    normal_sum += normal;
  }

  double mean = 0.0;
  for (double mu : fit.pair_mu) mean += mu;
  mean /= n;
  double var = 0.0;
  for (double mu : fit.pair_mu) var += (mu - mean) * (mu - mean);
  fit.mu = mean;
  fit.mu_std = n > 1 ? std::sqrt(var / (n - 1)) : 0.0;
  std::vector<double> sorted = fit.pair_mu;
  const auto mid = sorted.begin() + n / 2;
  std::nth_element(sorted.begin(), mid, sorted.end());
  fit.mu_median = *mid;
  if (n % 2 == 0) fit.mu_median = 0.5 * (fit.mu_median + *std::max_element(sorted.begin(), mid));
  fit.normal = normal_sum.normalized();
  return fit;
}

}  // namespace surfmap
