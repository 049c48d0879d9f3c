#include "server/estimate/path_pairing.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"

namespace surfmap {
namespace {

// One segment of the forward polyline, prepared once: every reverse sample
// is projected onto a few of them (and the first onto all).
struct Segment {
  Eigen::Vector3d a;
  Eigen::Vector3d ab;
  double inverse_length2;  // 0 for a degenerate segment
};

struct Foot {
  double distance2;  // squared: compared far more often than reported
  int segment;
  double t;  // 0..1 along the segment
};

// Closest point to q on segment k.
Foot ProjectOnSegment(const std::vector<Segment>& segments, int k, const Eigen::Vector3d& q) {
  const Segment& seg = segments[k];
  const Eigen::Vector3d aq = q - seg.a;
  const double t = std::clamp(aq.dot(seg.ab) * seg.inverse_length2, 0.0, 1.0);
  return {(aq - t * seg.ab).squaredNorm(), k, t};
}

}  // namespace

bool PairingOptions::IsValid(std::string* why) const {
  auto fail = [&](const char* message) {
    if (why) *why = message;
    return false;
  };
  if (!(max_offset_floor_mm > 0.0)) return fail("max_offset_floor_mm must be > 0");
  if (!(max_offset_fraction >= 0.0)) return fail("max_offset_fraction must be >= 0");
  if (!(min_coverage_fraction > 0.0 && min_coverage_fraction <= 1.0)) {
    return fail("min_coverage_fraction must be in (0, 1]");
  }
  return true;
}

absl::StatusOr<PathPairing> PairPasses(std::span<const DragSample> forward,
                                       std::span<const DragSample> reverse,
                                       const PairingOptions& options) {
  if (forward.size() < 2) {
    return absl::InvalidArgumentError(
        absl::StrCat("forward pass has ", forward.size(), " sample(s); pairing needs at least 2"));
  }
  if (reverse.empty()) return absl::InvalidArgumentError("reverse pass has no samples");

  PathPairing pairing;
  const int nf = static_cast<int>(forward.size());
  const int nr = static_cast<int>(reverse.size());
  pairing.forward_s.resize(nf);
  pairing.reverse_s.resize(nr);
  // The forward polyline is the positions smoothed by a centred moving
  // average (up to +-2 samples, symmetric near the ends): position noise
  // zig-zags the raw polyline and inflates its arc length where the probe moves
  // slowly (0.005 mm noise at the ramps: +1.4% on a 20 mm path); the average
  // cuts that ~5-fold, and on a 40 mm radius its inward bias is ~1e-4 mm.
  std::vector<Eigen::Vector3d> path(nf);
  for (int i = 0; i < nf; ++i) {
    const int h = std::min({2, i, nf - 1 - i});
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (int m = i - h; m <= i + h; ++m) sum += forward[m].position;
    path[i] = sum / (2 * h + 1);
  }
  pairing.forward_s[0] = 0.0;
  for (int i = 1; i < nf; ++i) {
    pairing.forward_s[i] = pairing.forward_s[i - 1] + (path[i] - path[i - 1]).norm();
  }
  pairing.path_length_mm = pairing.forward_s[nf - 1];
  if (!(pairing.path_length_mm > 0.0)) {
    return absl::InvalidArgumentError("forward pass does not move (path length 0 mm)");
  }
  const double max_offset = std::max(options.max_offset_floor_mm,
                                     options.max_offset_fraction * pairing.path_length_mm);
  const int segments = nf - 1;
  std::vector<Segment> segment(segments);
  for (int m = 0; m < segments; ++m) {
    const Eigen::Vector3d ab = path[m + 1] - path[m];
    const double length2 = ab.squaredNorm();
    segment[m] = {path[m], ab, length2 > 0.0 ? 1.0 / length2 : 0.0};
  }
  const auto arc_length = [&](const Foot& foot) {
    const int m = foot.segment;
    return pairing.forward_s[m] + foot.t * (pairing.forward_s[m + 1] - pairing.forward_s[m]);
  };

  // The reverse pass runs from the forward end back to its start, so visiting
  // its samples from last to first walks the forward polyline forwards.
  int k = 0;
  {
    // The first foot is found by a full scan: the reverse pass may stop short.
    double best = std::numeric_limits<double>::infinity();
    for (int m = 0; m < segments; ++m) {
      const Foot foot = ProjectOnSegment(segment, m, reverse[nr - 1].position);
      if (foot.distance2 < best) {
        best = foot.distance2;
        k = m;
      }
    }
  }
  double previous_s = 0.0;
  double max_seen = 0.0;  // squared until the loop ends
  int worst = nr - 1;
  for (int j = nr - 1; j >= 0; --j) {
    const Eigen::Vector3d& q = reverse[j].position;
    // Look ahead as far as the probe moved since the previous reverse sample,
    // plus a margin (0.1 mm, 20x the position noise of a typical rig).
    const double moved = j == nr - 1 ? 0.0 : (q - reverse[j + 1].position).norm();
    const double reach = std::max(previous_s, pairing.forward_s[k]) + moved + 0.1;
    Foot best = ProjectOnSegment(segment, k, q);
    for (int m = k + 1; m < segments && pairing.forward_s[m] <= reach; ++m) {
      const Foot foot = ProjectOnSegment(segment, m, q);
      if (foot.distance2 < best.distance2) best = foot;
    }
    k = best.segment;
    previous_s = arc_length(best);
    pairing.reverse_s[j] = previous_s;
    if (best.distance2 > max_seen) {
      max_seen = best.distance2;
      worst = j;
    }
  }
  max_seen = std::sqrt(max_seen);
  pairing.max_offset_mm = max_seen;
  if (max_seen > max_offset) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "reverse pass does not retrace the forward path: reverse sample %d (t=%.3f s) is %.3f mm "
        "from the forward path (limit %.3f mm = max(%.3g mm, %.3g of the %.3f mm path))",
        worst, reverse[worst].t, max_seen, max_offset, options.max_offset_floor_mm,
        options.max_offset_fraction, pairing.path_length_mm));
  }
  const auto [lo, hi] = std::minmax_element(pairing.reverse_s.begin(), pairing.reverse_s.end());
  pairing.covered_from_mm = *lo;
  pairing.covered_to_mm = *hi;
  const double covered = pairing.covered_to_mm - pairing.covered_from_mm;
  if (covered < options.min_coverage_fraction * pairing.path_length_mm) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "reverse pass covers only %.3f of the %.3f mm forward path (%.0f%%, need %.0f%%)", covered,
        pairing.path_length_mm, 100.0 * covered / pairing.path_length_mm,
        100.0 * options.min_coverage_fraction));
  }
  return pairing;
}

}  // namespace surfmap
