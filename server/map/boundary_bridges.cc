#include "server/map/boundary_bridges.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <tuple>
#include <utility>

#include <Eigen/Geometry>

namespace surfmap {
namespace {

double CosDegrees(double degrees) { return std::cos(degrees * std::numbers::pi / 180.0); }

// Whether `direction` (from an end's mark) turns from the end's chain
// direction `out` by at most acos(min_cos), in the plane of `normal`.
bool Straight(const Eigen::Vector3d& direction, const Eigen::Vector3d& out, const Eigen::Vector3d& normal,
              double min_cos) {
  const Eigen::Vector3d along = InPlane(direction, normal), chain = InPlane(out, normal);
  if (along.norm() < 1e-9 || chain.norm() < 1e-9) return false;
  return along.normalized().dot(chain.normalized()) >= min_cos;
}

struct Bridge {
  double length = 0.0;
  int first = -1;  // indices into the chain ends
  int second = -1;
  int region = -1;                                           // R, on both ends
  Eigen::Vector3d towards_region = Eigen::Vector3d::Zero();  // unit, across the chord
  std::vector<BoundarySegment> stretches;                    // one far region each
};

// The region of the data point nearest x on the side away from
// `towards_region`, other than `region`, within `reach`; -1 when none.
int FarRegion(const LabelledPointGrid& data, const Eigen::Vector3d& x, const Eigen::Vector3d& towards_region,
              int region, double reach) {
  int best = -1;
  double best_d2 = reach * reach;
  data.ForEachNear(x, x, reach, [&](const LabelledPoint& point) {
    if (point.label == region) return;
    const Eigen::Vector3d d = point.point - x;
    if (d.dot(towards_region) >= 0.0) return;
    if (const double d2 = d.squaredNorm(); d2 < best_d2) best_d2 = d2, best = point.label;
  });
  return best;
}

// What contradicts a stretch of a bridge. A link's check refuses data a
// quarter of a millimetre on the wrong side of its chord; a bridge's chord is
// known only from its two ends, up to 60 mm apart, and the pieces beside it
// end where their drags' change tests and the map's split put the changes:
// on big_block_m (500 Hz, seed 7) both edges of the strip through the patch
// had masonite data 0.6-1.9 mm on the strip's side, the ends of parts that
// the split cut from drags across the whole strip. So a stretch is
// contradicted by data of a third region within the corridor of it (as a
// link), or by data on the wrong side by more than bridge_tolerance_mm, out
// to twice that: a drag that crossed the chord where the bridge says no
// boundary is puts its points there.
CorridorCheck BridgeCheck(const BoundaryLinkOptions& o) {
  return {o.corridor_mm, o.bridge_tolerance_mm, 2.0 * o.bridge_tolerance_mm};
}

// The runs [begin, end) of equal values in values[0..n) (the last sample,
// values[n], belongs to the last run).
std::vector<std::pair<int, int>> Runs(const std::vector<int>& values, int n) {
  std::vector<std::pair<int, int>> runs;
  for (int begin = 0; begin < n;) {
    int end = begin + 1;
    while (end < n && values[end] == values[begin]) ++end;
    runs.emplace_back(begin, end);
    begin = end;
  }
  return runs;
}

// The bridge from p to q with `region` on the side of `towards_region`, cut
// into stretches of one far region each; empty when data contradicts one of
// them, or when both ends have the same far region and nothing else lies
// beyond the chord (a chain to extend, not a bridge).
std::vector<BoundarySegment> Stretches(const ChangeMark& p, const ChangeMark& q, int region,
                                       const Eigen::Vector3d& towards_region, int far1, int far2,
                                       const LabelledPointGrid& data, const BoundaryLinkOptions& o) {
  // The surface bows off the chord; the parabola through p, the bowed middle
  // and q stands for it, as in the corridor check.
  const Eigen::Vector3d bow = ChordBow(p.position, q.position, p.normal, q.normal);
  auto at = [&](double t) -> Eigen::Vector3d {
    return p.position + t * (q.position - p.position) + 4.0 * t * (1.0 - t) * bow;
  };
  const double length = (q.position - p.position).norm();
  const double step = o.max_dot_chord_mm;
  const int n = std::max(1, static_cast<int>(std::ceil(length / step)));
  std::vector<int> far(n + 1);
  bool third = false;
  for (int k = 0; k <= n; ++k) {
    const double t = static_cast<double>(k) / n;
    far[k] = FarRegion(data, at(t), towards_region, region, o.max_length_mm);
    if (far[k] < 0) far[k] = t < 0.5 ? far1 : far2;
    third |= far[k] != far1 && far[k] != far2;
  }
  if (far1 == far2 && !third) return {};
  const std::vector<std::pair<int, int>> runs = Runs(far, n);
  // A third region beyond the chord for less than a link's length is as
  // likely data beyond a narrow neighbour that no drag measured there as a
  // region the boundary meets (held-out pebble: a 6 mm masonite strip's
  // edge bridged against the glass beyond it for 9.6 mm); a patch the
  // boundary runs along shows for longer (big_block_m: 35 mm).
  for (const auto& [begin, end] : runs) {
    if (far[begin] != far1 && far[begin] != far2 && (end - begin) * length / n < o.max_length_mm) return {};
  }
  // Where the far region changes, the data of both lie beside the chord:
  // each stretch is checked clear of its inner ends by the corridor and a step.
  const double margin = (o.corridor_mm + step) / length;
  std::vector<BoundarySegment> out;
  for (const auto& [begin, end] : runs) {
    const double t0 = begin == 0 ? 0.0 : (begin - 0.5) / n;
    const double t1 = end == n ? 1.0 : (end - 0.5) / n;
    const int far_region = far[begin];  // clang 14 cannot capture a structured binding
    auto segment = [&](double from, double to) {
      const Eigen::Vector3d a = at(from), b = at(to);
      return BoundarySegment{a, b, towards_region, region, far_region, at(0.5 * (from + to)) - 0.5 * (a + b)};
    };
    const double c0 = begin == 0 ? t0 : t0 + margin, c1 = end == n ? t1 : t1 - margin;
    if (c1 > c0 && SegmentContradicted(segment(c0, c1), data, BridgeCheck(o))) return {};
    out.push_back(segment(t0, t1));
  }
  return out;
}

// The bridge between two chain ends, if they make one. Ends of the same two
// regions (the two edges of a strip through a patch end outside it) may keep
// either on the near side: the one whose far side changes to a third region
// is kept; when both do, which is meant is not known and none is drawn.
bool Bridges(const std::vector<ChangeMark>& marks, const ChainEnd& e1, const ChainEnd& e2,
             const LabelledPointGrid& data, const BoundaryLinkOptions& o, Bridge* out) {
  const ChangeMark& p = marks[e1.mark];
  const ChangeMark& q = marks[e2.mark];
  if (p.drag == q.drag || p.normal.dot(q.normal) < CosDegrees(o.max_corner_normal_deg)) return false;
  const Eigen::Vector3d chord = q.position - p.position;
  const double length = chord.norm();
  if (length < o.min_corner_link_mm || length > o.max_bridge_mm) return false;
  const double min_cos = CosDegrees(o.max_line_turn_deg);
  if (!Straight(chord, e1.out, p.normal, min_cos) || !Straight(-chord, e2.out, q.normal, min_cos)) return false;
  Eigen::Vector3d across = chord.cross((p.normal + q.normal).normalized());
  if (across.norm() < 1e-9) return false;
  across.normalize();
  int found = 0;
  for (int region : {e1.a, e1.b}) {
    if (region != e2.a && region != e2.b) continue;
    auto towards = [&](const ChainEnd& e) { return e.a == region ? e.towards_a : Eigen::Vector3d(-e.towards_a); };
    const double s1 = towards(e1).dot(across), s2 = towards(e2).dot(across);
    if (s1 * s2 <= 0.0) continue;
    const Eigen::Vector3d towards_region = s1 > 0.0 ? across : Eigen::Vector3d(-across);
    const int far1 = e1.a == region ? e1.b : e1.a, far2 = e2.a == region ? e2.b : e2.a;
    std::vector<BoundarySegment> stretches = Stretches(p, q, region, towards_region, far1, far2, data, o);
    if (stretches.empty()) continue;
    ++found;
    *out = {length, -1, -1, region, towards_region, std::move(stretches)};
  }
  return found == 1;
}

}  // namespace

std::vector<LabelledPoint> BoundaryBridgePoints(const std::vector<ChangeMark>& marks,
                                                const std::vector<DrawnLink>& links, const LabelledPointGrid& data,
                                                const BoundaryLinkOptions& o, int* bridges) {
  if (bridges != nullptr) *bridges = 0;
  std::vector<LabelledPoint> out;
  if (!(o.max_bridge_mm > 0.0)) return out;
  const std::vector<ChainEnd> ends = ChainEnds(marks, links, o.min_corner_link_mm, o.chain_ends_reach_past_short_links);
  std::vector<Bridge> candidates;
  for (int i = 0; i < static_cast<int>(ends.size()); ++i) {
    for (int j = i + 1; j < static_cast<int>(ends.size()); ++j) {
      Bridge bridge;
      if (!Bridges(marks, ends[i], ends[j], data, o, &bridge)) continue;
      bridge.first = i;
      bridge.second = j;
      candidates.push_back(std::move(bridge));
    }
  }
  std::sort(candidates.begin(), candidates.end(), [](const Bridge& x, const Bridge& y) {
    return x.length != y.length ? x.length < y.length : std::tie(x.first, x.second) < std::tie(y.first, y.second);
  });
  std::vector<bool> used(ends.size(), false);
  for (const Bridge& bridge : candidates) {
    if (used[bridge.first] || used[bridge.second]) continue;
    used[bridge.first] = used[bridge.second] = true;
    for (const BoundarySegment& s : bridge.stretches) AppendSegmentSeeds(s, o, &out);
    if (bridges != nullptr) ++*bridges;
  }
  return out;
}

}  // namespace surfmap
