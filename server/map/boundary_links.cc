#include "server/map/boundary_links.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>
#include <unordered_map>

#include <Eigen/Geometry>

namespace surfmap {
namespace {

// Data points by cell for corridor queries.
class PointGrid {
 public:
  PointGrid(const std::vector<LabelledPoint>& points, double cell) : points_(points), cell_(cell) {
    for (int i = 0; i < static_cast<int>(points.size()); ++i) cells_[Key(Cell(points[i].point))].push_back(i);
  }
  template <typename Fn>
  void ForEachNear(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double margin, const Fn& fn) const {
    const Eigen::Vector3i lo = Cell(a.cwiseMin(b) - Eigen::Vector3d::Constant(margin));
    const Eigen::Vector3i hi = Cell(a.cwiseMax(b) + Eigen::Vector3d::Constant(margin));
    for (int x = lo.x(); x <= hi.x(); ++x) {
      for (int y = lo.y(); y <= hi.y(); ++y) {
        for (int z = lo.z(); z <= hi.z(); ++z) {
          auto it = cells_.find(Key({x, y, z}));
          if (it == cells_.end()) continue;
          for (int i : it->second) fn(points_[i]);
        }
      }
    }
  }

 private:
  Eigen::Vector3i Cell(const Eigen::Vector3d& p) const { return (p / cell_).array().floor().cast<int>().matrix(); }
  static std::uint64_t Key(const Eigen::Vector3i& c) {
    return (static_cast<std::uint64_t>(c.x() & 0x1fffff) << 42) | (static_cast<std::uint64_t>(c.y() & 0x1fffff) << 21) |
           static_cast<std::uint64_t>(c.z() & 0x1fffff);
  }
  const std::vector<LabelledPoint>& points_;
  double cell_;
  std::unordered_map<std::uint64_t, std::vector<int>> cells_;
};

// Unit vector pointing to region `a`'s side at a mark, in its tangent plane.
Eigen::Vector3d TowardsA(const ChangeMark& m, int a) { return m.before == a ? Eigen::Vector3d(-m.direction) : m.direction; }

}  // namespace

std::vector<LabelledPoint> BoundaryLinkPoints(const std::vector<ChangeMark>& marks,
                                              const std::vector<LabelledPoint>& data,
                                              const BoundaryLinkOptions& o, int* links) {
  const int n = static_cast<int>(marks.size());
  const PointGrid grid(data, std::max(1.0, o.max_length_mm / 4.0));
  // Per mark and side along the boundary: the nearest consistent partner.
  std::vector<std::array<int, 2>> nearest(n, {-1, -1});
  std::vector<std::array<double, 2>> nearest_distance(n, {std::numeric_limits<double>::infinity(),
                                                          std::numeric_limits<double>::infinity()});
  auto consistent = [&](int i, int j, Eigen::Vector3d* side_normal, int* a_out, int* b_out) {
    const ChangeMark& p = marks[i];
    const ChangeMark& q = marks[j];
    const int a = std::min(p.before, p.after), b = std::max(p.before, p.after);
    if (a == b || std::min(q.before, q.after) != a || std::max(q.before, q.after) != b || p.drag == q.drag) return false;
    const Eigen::Vector3d chord = q.position - p.position;
    const double length = chord.norm();
    if (!(length > 1e-9) || length > o.max_length_mm) return false;
    const Eigen::Vector3d normal = (p.normal + q.normal).normalized();
    Eigen::Vector3d across = chord.cross(normal);
    if (across.norm() < 1e-9) return false;
    across.normalize();
    const double sp = TowardsA(p, a).dot(across), sq = TowardsA(q, a).dot(across);
    if (sp * sq <= 0.0 || std::abs(sp) < o.min_crossing_cos || std::abs(sq) < o.min_crossing_cos) return false;
    *side_normal = sp > 0 ? across : Eigen::Vector3d(-across);  // towards A
    *a_out = a;
    *b_out = b;
    return true;
  };
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d along = marks[i].normal.cross(marks[i].direction);  // roughly along the boundary
    for (int j = 0; j < n; ++j) {
      if (i == j) continue;
      Eigen::Vector3d towards_a;
      int a, b;
      if (!consistent(i, j, &towards_a, &a, &b)) continue;
      const Eigen::Vector3d chord = marks[j].position - marks[i].position;
      const int side = chord.dot(along) >= 0.0 ? 0 : 1;
      const double d = chord.norm();
      if (d < nearest_distance[i][side]) {
        nearest_distance[i][side] = d;
        nearest[i][side] = j;
      }
    }
  }
  std::set<std::pair<int, int>> pairs;
  for (int i = 0; i < n; ++i) {
    for (int j : nearest[i]) {
      if (j >= 0) pairs.emplace(std::min(i, j), std::max(i, j));
    }
  }
  std::vector<LabelledPoint> out;
  int accepted = 0;
  for (const auto& [i, j] : pairs) {
    Eigen::Vector3d towards_a;
    int a, b;
    if (!consistent(i, j, &towards_a, &a, &b)) continue;
    const Eigen::Vector3d p = marks[i].position, q = marks[j].position;
    const Eigen::Vector3d chord = q - p;
    const double length = chord.norm();
    const Eigen::Vector3d t = chord / length;
    bool contradicted = false;
    grid.ForEachNear(p, q, o.corridor_mm, [&](const LabelledPoint& x) {
      if (contradicted) return;
      const Eigen::Vector3d r = x.point - p;
      const double along = r.dot(t);
      if (along < 0.0 || along > length) return;
      const Eigen::Vector3d off = r - along * t;
      if (off.norm() > o.corridor_mm) return;
      const double side = off.dot(towards_a);  // > 0: A's side
      if (x.label != a && x.label != b) {
        contradicted = true;
      } else if ((x.label == a && side < -o.seed_offset_mm) || (x.label == b && side > o.seed_offset_mm)) {
        contradicted = true;
      }
    });
    if (contradicted) continue;
    ++accepted;
    const int steps = std::max(1, static_cast<int>(std::ceil(length / o.seed_spacing_mm)));
    for (int k = 0; k <= steps; ++k) {
      const Eigen::Vector3d on = p + (static_cast<double>(k) / steps) * chord;
      out.push_back({on + o.seed_offset_mm * towards_a, a});
      out.push_back({on - o.seed_offset_mm * towards_a, b});
    }
  }
  if (links != nullptr) *links = accepted;
  return out;
}

}  // namespace surfmap
