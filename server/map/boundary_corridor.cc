#include "server/map/boundary_corridor.h"

#include <algorithm>
#include <cmath>
#include <utility>

namespace surfmap {

LabelledPointGrid::LabelledPointGrid(std::vector<LabelledPoint> points, double cell)
    : points_(std::move(points)), cell_(cell) {
  for (int i = 0; i < static_cast<int>(points_.size()); ++i) cells_[Key(Cell(points_[i].point))].push_back(i);
}

std::uint64_t LabelledPointGrid::Key(const Eigen::Vector3i& c) {
  return (static_cast<std::uint64_t>(c.x() & 0x1fffff) << 42) | (static_cast<std::uint64_t>(c.y() & 0x1fffff) << 21) |
         static_cast<std::uint64_t>(c.z() & 0x1fffff);
}

Eigen::Vector3d ChordBow(const Eigen::Vector3d& p, const Eigen::Vector3d& q, const Eigen::Vector3d& n_p,
                         const Eigen::Vector3d& n_q) {
  const Eigen::Vector3d mean = n_p + n_q;
  if (!(mean.norm() > 1e-9)) return Eigen::Vector3d::Zero();
  const double theta = std::acos(std::clamp(n_p.normalized().dot(n_q.normalized()), -1.0, 1.0));
  const double sagitta = 0.5 * (q - p).norm() * std::tan(0.25 * theta);
  const double opens = (n_q - n_p).dot(q - p);
  return (opens >= 0.0 ? sagitta : -sagitta) * mean.normalized();
}

bool SegmentContradicted(const BoundarySegment& s, const LabelledPointGrid& data, const CorridorCheck& check) {
  const Eigen::Vector3d chord = s.q - s.p;
  const double length = chord.norm();
  if (!(length > 1e-9)) return false;
  const Eigen::Vector3d t = chord / length;
  const double reach = std::max(check.reach_mm, check.third_region_mm);
  bool contradicted = false;
  data.ForEachNear(s.p, s.q, reach + s.bow.norm(), [&](const LabelledPoint& x) {
    if (contradicted) return;
    const Eigen::Vector3d r = x.point - s.p;
    const double along = r.dot(t);
    if (along < 0.0 || along > length) return;
    // Off the surface's arc over the chord, not the chord itself.
    const double u = along / length;
    const Eigen::Vector3d off = r - along * t - 4.0 * u * (1.0 - u) * s.bow;
    const double distance = off.norm();
    if (x.label != s.a && x.label != s.b) {
      contradicted = distance <= check.third_region_mm;
    } else if (distance <= check.reach_mm) {
      const double side = off.dot(s.towards_a);  // > 0: a's side
      contradicted = (x.label == s.a && side < -check.wrong_side_mm) || (x.label == s.b && side > check.wrong_side_mm);
    }
  });
  return contradicted;
}

bool SegmentContradicted(const BoundarySegment& s, const LabelledPointGrid& data, const BoundaryLinkOptions& o) {
  return SegmentContradicted(s, data, CorridorCheck{o.corridor_mm, o.seed_offset_mm, o.corridor_mm});
}

void AppendSegmentSeeds(const BoundarySegment& s, const BoundaryLinkOptions& o, std::vector<LabelledPoint>* out) {
  const Eigen::Vector3d chord = s.q - s.p;
  const int steps = std::max(1, static_cast<int>(std::ceil(chord.norm() / o.seed_spacing_mm)));
  for (int k = 0; k <= steps; ++k) {
    const Eigen::Vector3d on = s.p + (static_cast<double>(k) / steps) * chord;
    out->push_back({on + o.seed_offset_mm * s.towards_a, s.a});
    out->push_back({on - o.seed_offset_mm * s.towards_a, s.b});
  }
}

}  // namespace surfmap
