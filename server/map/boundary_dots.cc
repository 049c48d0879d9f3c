#include "server/map/boundary_dots.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <optional>
#include <utility>

#include <Eigen/Dense>

namespace surfmap {
namespace {

// A circle in the plane through `origin` with unit normal `normal`.
struct Circle {
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
  Eigen::Vector3d e1 = Eigen::Vector3d::UnitX(), e2 = Eigen::Vector3d::UnitY();  // in-plane basis
  double radius = 0.0;
  // A mark that may lie off the circle by max_dot_outlier_mm (FitExcusingOne),
  // and where it lies: its drag's data there may lie inside the circle.
  int excused = -1;
  Eigen::Vector3d excused_at = Eigen::Vector3d::Zero();
  Eigen::Vector3d At(double angle) const { return centre + radius * (std::cos(angle) * e1 + std::sin(angle) * e2); }
};

// The least-squares circle through the marks in their mean tangent plane
// (Kasa's algebraic fit), if the marks lie on one piece of surface.
std::optional<Circle> FitCircle(const std::vector<ChangeMark>& marks, const std::vector<int>& group,
                                const BoundaryLinkOptions& o) {
  const std::optional<MarksPlane> plane = PlaneOfMarks(marks, group, o);
  if (!plane) return std::nullopt;
  Circle c;
  c.normal = plane->normal;
  c.e1 = plane->e1;
  c.e2 = plane->e2;
  const int n = static_cast<int>(group.size());
  Eigen::MatrixXd a(n, 3);
  Eigen::VectorXd b(n);
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector2d q = plane->At(marks[group[i]].position);
    a.row(i) << 2.0 * q.x(), 2.0 * q.y(), 1.0;
    b(i) = q.squaredNorm();
  }
  const Eigen::Vector3d sol = a.colPivHouseholderQr().solve(b);
  const double r2 = sol(2) + sol(0) * sol(0) + sol(1) * sol(1);
  if (!(r2 > 0.0) || !std::isfinite(r2)) return std::nullopt;
  c.centre = plane->Point(sol.head<2>());
  c.radius = std::sqrt(r2);
  return c;
}

// In-plane distance from the circle's centre, and the distance off its plane.
std::pair<double, double> Polar(const Circle& c, const Eigen::Vector3d& p) {
  const Eigen::Vector3d d = p - c.centre;
  return {InPlane(d, c.normal).norm(), std::abs(d.dot(c.normal))};
}

double Residual(const Circle& c, const ChangeMark& mark) { return std::abs(Polar(c, mark.position).first - c.radius); }

// The circle for a group: the least-squares fit through all its marks; or,
// when one lies off that by more than max_dot_residual_mm and the group has
// min_dot_crossings_to_excuse_one, the fit through the others with the one
// farthest off excused (EdgeAngles holds it to max_dot_outlier_mm).
std::optional<Circle> FitExcusingOne(const std::vector<ChangeMark>& marks, const std::vector<int>& group,
                                     const BoundaryLinkOptions& o) {
  std::optional<Circle> all = FitCircle(marks, group, o);
  if (!all || static_cast<int>(group.size()) < o.min_dot_crossings_to_excuse_one) return all;
  const auto farthest = std::max_element(group.begin(), group.end(), [&](int a, int b) {
    return Residual(*all, marks[a]) < Residual(*all, marks[b]);
  });
  if (Residual(*all, marks[*farthest]) <= o.max_dot_residual_mm) return all;
  std::vector<int> others;
  for (int m : group) {
    if (m != *farthest) others.push_back(m);
  }
  std::optional<Circle> rest = FitCircle(marks, others, o);
  if (rest) rest->excused = *farthest, rest->excused_at = marks[*farthest].position;
  return rest ? rest : all;
}

// Calls fn(x, r) for each data point x within the circle's ring (in-plane
// distance r from its centre under dot_ring_radii radii), skipping points
// farther off its plane than half that: another part of the object.
template <typename Fn>
void ForEachInRing(const Circle& c, const LabelledPointGrid& data, const BoundaryLinkOptions& o, const Fn& fn) {
  const double ring = o.dot_ring_radii * c.radius;
  const Eigen::Vector3d span = Eigen::Vector3d::Constant(ring);
  data.ForEachNear(c.centre - span, c.centre + span, 0.0, [&](const LabelledPoint& x) {
    const auto [r, off] = Polar(c, x.point);
    if (off <= 0.5 * ring && r < ring) fn(x, r);
  });
}

// The widest gap between the angles (radians, any order) round the circle.
double WidestGap(std::vector<double> angles) {
  std::sort(angles.begin(), angles.end());
  double widest = angles.front() + 2.0 * std::numbers::pi - angles.back();
  for (std::size_t k = 1; k < angles.size(); ++k) widest = std::max(widest, angles[k] - angles[k - 1]);
  return widest;
}

double AngleOf(const Circle& c, const Eigen::Vector3d& p) {
  const Eigen::Vector3d d = p - c.centre;
  return std::atan2(d.dot(c.e2), d.dot(c.e1));
}

// The angles of the crossings of `group` round circle c if they make a dot's
// edge with `inner` inside (every crossing on the circle, at least three
// entering steeply), else nothing.
std::optional<std::vector<double>> EdgeAngles(const std::vector<ChangeMark>& marks, const std::vector<int>& group,
                                              const Circle& c, int inner, const BoundaryLinkOptions& o) {
  if (c.radius < o.corridor_mm || c.radius > o.max_dot_radius_mm) return std::nullopt;
  std::vector<double> angles;
  int steep = 0;
  for (int m : group) {
    const Eigen::Vector3d d = InPlane(marks[m].position - c.centre, c.normal);
    const double tolerance = m == c.excused ? o.max_dot_outlier_mm : o.max_dot_residual_mm;
    if (std::abs(d.norm() - c.radius) > tolerance) return std::nullopt;
    const Eigen::Vector3d in = InPlane(TowardsA(marks[m], inner), c.normal);
    if (in.norm() < 1e-9) return std::nullopt;
    if (in.normalized().dot(-d.normalized()) >= o.min_extension_crossing_cos) {
      ++steep;
    } else if (!o.dot_grazing_crossings_on_circle) {
      return std::nullopt;
    }
    angles.push_back(AngleOf(c, marks[m].position));
  }
  if (steep < 3) return std::nullopt;
  return angles;
}

// Whether data of another region just outside the circle (out to
// dot_ring_radii of its radius) close the crossings' gap: with their
// angles, the crossings' widest gap is under 180 degrees. A patch's corner
// crossed near its tip has its crossings on a circle too, but beyond the
// gap lies the patch itself, never another region.
bool GapClosedByData(const Circle& c, std::vector<double> angles, int inner, const LabelledPointGrid& data,
                     const BoundaryLinkOptions& o) {
  ForEachInRing(c, data, o, [&](const LabelledPoint& x, double r) {
    if (x.label != inner && r > c.radius + o.corridor_mm) angles.push_back(AngleOf(c, x.point));
  });
  return WidestGap(std::move(angles)) < std::numbers::pi;
}

// Whether the marks of `group` make a dot on circle c with `inner` inside:
// their crossings surround its centre, or span min_dot_arc_deg and data of
// other regions close the rest.
bool IsDot(const std::vector<ChangeMark>& marks, const std::vector<int>& group, const Circle& c, int inner,
           const LabelledPointGrid& data, const BoundaryLinkOptions& o) {
  const std::optional<std::vector<double>> angles = EdgeAngles(marks, group, c, inner, o);
  if (!angles) return false;
  const double widest = WidestGap(*angles);
  if (widest < std::numbers::pi) return true;
  if (widest >= 2.0 * std::numbers::pi - o.min_dot_arc_deg * std::numbers::pi / 180.0) return false;
  return GapClosedByData(c, *angles, inner, data, o);
}

// The circle's chords, each a boundary segment with `inner` on its inside.
std::vector<BoundarySegment> Chords(const Circle& c, int inner, int outer, const BoundaryLinkOptions& o) {
  const int steps = std::max(12, static_cast<int>(std::ceil(2.0 * std::numbers::pi * c.radius / o.max_dot_chord_mm)));
  std::vector<BoundarySegment> out;
  for (int k = 0; k < steps; ++k) {
    const double a0 = 2.0 * std::numbers::pi * k / steps, a1 = 2.0 * std::numbers::pi * (k + 1) / steps;
    const Eigen::Vector3d p = c.At(a0), q = c.At(a1);
    const Eigen::Vector3d inwards = (c.centre - 0.5 * (p + q)).normalized();
    // BoundarySegment's a is the region on towards_a's side.
    out.push_back({p, q, inwards, inner, outer, Eigen::Vector3d::Zero()});
  }
  return out;
}

// Whether data of another region lie inside the circle, or the inner
// region's data in the ring outside it: the region is larger, or not round.
// The data of an excused crossing's drag near it are its own offset.
bool RingContradicted(const Circle& c, int inner, const LabelledPointGrid& data, const BoundaryLinkOptions& o) {
  bool contradicted = false;
  ForEachInRing(c, data, o, [&](const LabelledPoint& x, double r) {
    if (c.excused >= 0 && (x.point - c.excused_at).norm() <= o.max_dot_outlier_mm) return;
    if (r < c.radius - o.corridor_mm && x.label != inner) contradicted = true;
    if (r > c.radius + o.corridor_mm && x.label == inner) contradicted = true;
  });
  return contradicted;
}

// The chords no data contradict (checked as for a link, with
// max_dot_data_offset_mm for the wrong side's tolerance), or nothing when
// more than max_dot_contradicted_chord_share of them are contradicted.
std::optional<std::vector<BoundarySegment>> UncontradictedChords(std::vector<BoundarySegment> chords,
                                                                 const LabelledPointGrid& data,
                                                                 const BoundaryLinkOptions& o) {
  const CorridorCheck near_circle{o.corridor_mm, o.max_dot_data_offset_mm, o.corridor_mm};
  std::vector<bool> contradicted;
  for (const BoundarySegment& s : chords) contradicted.push_back(SegmentContradicted(s, data, near_circle));
  return surfmap::UncontradictedChords(std::move(chords), contradicted, o);
}

// The dot on circle c with `inner` inside and `outer` outside, if its
// crossings and the data make one (boundary_dots.h).
std::optional<BoundaryDot> DotOn(const Circle& c, const std::vector<ChangeMark>& marks, const std::vector<int>& group,
                                 int inner, int outer, const LabelledPointGrid& data, const BoundaryLinkOptions& o) {
  if (!IsDot(marks, group, c, inner, data, o) || RingContradicted(c, inner, data, o)) return std::nullopt;
  std::optional<std::vector<BoundarySegment>> chords = UncontradictedChords(Chords(c, inner, outer, o), data, o);
  if (!chords) return std::nullopt;
  return BoundaryDot{group, inner, outer, std::move(*chords)};
}

}  // namespace

std::vector<BoundaryDot> FindDots(const std::vector<ChangeMark>& marks, const LabelledPointGrid& data,
                                  const BoundaryLinkOptions& o) {
  std::vector<BoundaryDot> dots;
  if (!(o.max_dot_radius_mm > 0.0)) return dots;
  std::map<std::pair<int, int>, std::vector<int>> by_pair;
  for (int m = 0; m < static_cast<int>(marks.size()); ++m) {
    const int a = std::min(marks[m].before, marks[m].after), b = std::max(marks[m].before, marks[m].after);
    if (a != b && a >= 0) by_pair[{a, b}].push_back(m);
  }
  for (const auto& [pair, members] : by_pair) {
    for (const std::vector<int>& group : GroupMarks(marks, members, 2.0 * o.max_dot_radius_mm)) {
      if (group.size() < 3) continue;
      const std::optional<Circle> circle = FitExcusingOne(marks, group, o);
      if (!circle) continue;
      for (const auto& [inner, outer] : {pair, std::pair<int, int>{pair.second, pair.first}}) {
        std::optional<BoundaryDot> dot = DotOn(*circle, marks, group, inner, outer, data, o);
        if (dot) dots.push_back(std::move(*dot));
      }
    }
  }
  return dots;
}

}  // namespace surfmap
