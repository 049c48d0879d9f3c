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

bool SegmentContradicted(const BoundarySegment& s, const LabelledPointGrid& data, const BoundaryLinkOptions& o) {
  const Eigen::Vector3d chord = s.q - s.p;
  const double length = chord.norm();
  if (!(length > 1e-9)) return false;
  const Eigen::Vector3d t = chord / length;
  bool contradicted = false;
  data.ForEachNear(s.p, s.q, o.corridor_mm + s.bow.norm(), [&](const LabelledPoint& x) {
    if (contradicted) return;
    const Eigen::Vector3d r = x.point - s.p;
    const double along = r.dot(t);
    if (along < 0.0 || along > length) return;
    // Off the surface's arc over the chord, not the chord itself.
    const double u = along / length;
    const Eigen::Vector3d off = r - along * t - 4.0 * u * (1.0 - u) * s.bow;
    if (off.norm() > o.corridor_mm) return;
    const double side = off.dot(s.towards_a);  // > 0: a's side
    if (x.label != s.a && x.label != s.b) {
      contradicted = true;
    } else if ((x.label == s.a && side < -o.seed_offset_mm) || (x.label == s.b && side > o.seed_offset_mm)) {
      contradicted = true;
    }
  });
  return contradicted;
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
