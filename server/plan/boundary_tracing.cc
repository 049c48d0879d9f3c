#include "server/plan/boundary_tracing.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>
#include "server/geometry/segment_distance.h"

namespace surfmap {
namespace {

// Unit tangent along the boundary at a crossing: n x d.
Eigen::Vector3d Along(const ChangeMark& m) {
  const Eigen::Vector3d t = m.normal.cross(m.direction);
  const double norm = t.norm();
  return norm > 1e-12 ? Eigen::Vector3d(t / norm) : Eigen::Vector3d::Zero();
}

// Towards the lower-numbered region at a crossing.
Eigen::Vector3d TowardsFirstRegion(const ChangeMark& m) {
  return m.before < m.after ? Eigen::Vector3d(-m.direction) : m.direction;
}

bool SameBoundary(const ChangeMark& p, const ChangeMark& q) {
  return p.drag != q.drag && std::min(p.before, p.after) == std::min(q.before, q.after) &&
         std::max(p.before, p.after) == std::max(q.before, q.after) &&
         TowardsFirstRegion(p).dot(TowardsFirstRegion(q)) > 0.0;
}

// Whether mark i has a crossing of its boundary within the link length on
// `side` of it, roughly along the boundary (within 60 degrees of +/- t).
bool HasPartner(const std::vector<ChangeMark>& marks, int i, int side, const BoundaryTraceOptions& o) {
  const Eigen::Vector3d along = side * Along(marks[i]);
  for (int j = 0; j < static_cast<int>(marks.size()); ++j) {
    if (j == i || !SameBoundary(marks[i], marks[j])) continue;
    const Eigen::Vector3d chord = marks[j].position - marks[i].position;
    const double length = chord.norm();
    if (length > o.link_mm || length < 1e-9) continue;
    if (chord.dot(along) >= 0.5 * length) return true;
  }
  return false;
}

}  // namespace

bool Explored(const TraceTarget& target, const std::vector<DragSegment>& drags, const BoundaryTraceOptions& o) {
  for (const DragSegment& s : drags) {
    const Eigen::Vector3d ab = s.b - s.a;
    const double length = ab.norm();
    // A point-like stretch has no direction: it explores only where it is.
    const bool crosses = length < 1e-9 || std::abs(ab.dot(target.direction)) >= o.min_crossing_cos * length;
    if (crosses && DistanceToSegment(target.point, s.a, s.b) <= o.explored_mm) return true;
  }
  return false;
}

double ContinuationError(const TraceTarget& target, const ChangeMark& mark, const RegionMap& map,
                         double half_window_mm, double corridor_mm) {
  const int regions = static_cast<int>(map.regions().size());
  if (mark.before < 0 || mark.after < 0 || mark.before >= regions || mark.after >= regions) return 0.0;
  const double jump = map.regions()[mark.after].statistics.mu - map.regions()[mark.before].statistics.mu;
  const int steps = std::max(1, static_cast<int>(std::ceil(2.0 * half_window_mm)));
  const double spacing = 2.0 * half_window_mm / steps;
  double wrong_mm = 0.0;
  for (int k = 0; k < steps; ++k) {
    const double x = -half_window_mm + (k + 0.5) * spacing;  // midpoints: none falls on the target itself
    const absl::StatusOr<MapValue> value = map.ValueAtPosition(target.point + x * target.direction);
    if (!value.ok()) continue;
    if (value->region != (x < 0.0 ? mark.before : mark.after)) wrong_mm += spacing;
  }
  return wrong_mm * 2.0 * corridor_mm * jump * jump;
}

std::vector<TraceTarget> OpenTraceTargets(const std::vector<ChangeMark>& marks, const std::vector<DragSegment>& drags,
                                          const BoundaryTraceOptions& o) {
  std::vector<TraceTarget> out;
  const double step = o.step_share * o.link_mm;
  for (int i = 0; i < static_cast<int>(marks.size()); ++i) {
    const Eigen::Vector3d along = Along(marks[i]);
    if (along.isZero() || !marks[i].direction.allFinite()) continue;
    for (int side : {+1, -1}) {
      if (HasPartner(marks, i, side, o)) continue;
      TraceTarget t;
      t.point = marks[i].position + side * step * along;
      t.direction = marks[i].direction.normalized();
      t.mark = i;
      t.side = side;
      if (!Explored(t, drags, o)) out.push_back(t);
    }
  }
  return out;
}

}  // namespace surfmap
