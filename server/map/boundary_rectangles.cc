#include "server/map/boundary_rectangles.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <numbers>
#include <optional>
#include <utility>

namespace surfmap {
namespace {

// The plane the rectangle is fitted in, and how far off it (along its
// normal) the patch's surface lies: data beyond are another sheet of the
// object (OnPatchSheet) and do not refuse the patch (AreaContradicted); a
// chord's outer region is still the nearest data's beyond it, on any sheet.
struct Plane : MarksPlane {
  double off_lo = -std::numeric_limits<double>::infinity(), off_hi = std::numeric_limits<double>::infinity();
  bool OnSheet(const Eigen::Vector3d& p) const { return Off(p) >= off_lo && Off(p) <= off_hi; }
};

// Sets the band off the plane where the patch's surface lies: the
// crossings' own distances off it, widened by 2 corridor_mm each way (a
// label 16 mm across a handle of radius 15 bulges 2.3 mm over the chord
// through its edges). Data farther off lie on another sheet of the object:
// scan_handle_m's label through the service (seed 2) was refused by the
// nylon butt's data 8 mm below its plane, and by the tpe 3.5 mm below,
// where the handle curves away (docs/method.md).
void OnPatchSheet(const std::vector<ChangeMark>& marks, const std::vector<int>& group, const BoundaryLinkOptions& o,
                  Plane* plane) {
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (int m : group) {
    const double off = plane->Off(marks[m].position);
    lo = std::min(lo, off), hi = std::max(hi, off);
  }
  plane->off_lo = lo - 2.0 * o.corridor_mm;
  plane->off_hi = hi + 2.0 * o.corridor_mm;
}

// The plane of the marks (PlaneOfMarks), with the patch's sheet.
std::optional<Plane> PlaneOf(const std::vector<ChangeMark>& marks, const std::vector<int>& group,
                             const BoundaryLinkOptions& o) {
  const std::optional<MarksPlane> fitted = PlaneOfMarks(marks, group, o);
  if (!fitted) return std::nullopt;
  Plane plane{*fitted};
  if (o.rectangle_data_on_patch_sheet) OnPatchSheet(marks, group, o, &plane);
  return plane;
}

// A rectangle in plane coordinates turned by `angle`: in the turned
// coordinates u = (cos, sin) . q, v = (-sin, cos) . q its sides are
// u = lo.x() (side 0), u = hi.x() (1), v = lo.y() (2), v = hi.y() (3).
struct Rectangle {
  double angle = 0.0;
  Eigen::Vector2d lo = Eigen::Vector2d::Zero(), hi = Eigen::Vector2d::Zero();
  Eigen::Vector2d Turned(const Eigen::Vector2d& q) const {
    const double c = std::cos(angle), s = std::sin(angle);
    return {c * q.x() + s * q.y(), -s * q.x() + c * q.y()};
  }
  Eigen::Vector2d Unturned(const Eigen::Vector2d& t) const {
    const double c = std::cos(angle), s = std::sin(angle);
    return {c * t.x() - s * t.y(), s * t.x() + c * t.y()};
  }
  // Signed distance inwards from side k's line of the turned point t.
  double Depth(int k, const Eigen::Vector2d& t) const {
    switch (k) {
      case 0: return t.x() - lo.x();
      case 1: return hi.x() - t.x();
      case 2: return t.y() - lo.y();
      default: return hi.y() - t.y();
    }
  }
  // How far inside the rectangle t lies (negative: outside).
  double Depth(const Eigen::Vector2d& t) const {
    return std::min(std::min(Depth(0, t), Depth(1, t)), std::min(Depth(2, t), Depth(3, t)));
  }
  // Side k's inward unit normal, turned coordinates.
  static Eigen::Vector2d Inwards(int k) {
    static constexpr std::array<std::array<double, 2>, 4> kInwards = {{{1, 0}, {-1, 0}, {0, 1}, {0, -1}}};
    return {kInwards[k][0], kInwards[k][1]};
  }
  // Position along side k (its coordinate along the side's line).
  static double Along(int k, const Eigen::Vector2d& t) { return k < 2 ? t.y() : t.x(); }
  // Side k's ends along it.
  std::pair<double, double> Extent(int k) const { return k < 2 ? std::pair{lo.y(), hi.y()} : std::pair{lo.x(), hi.x()}; }
  Eigen::Vector2d OnSide(int k, double along) const {
    switch (k) {
      case 0: return {lo.x(), along};
      case 1: return {hi.x(), along};
      case 2: return {along, lo.y()};
      default: return {along, hi.y()};
    }
  }
  int NearestSide(const Eigen::Vector2d& t) const {
    int best = 0;
    for (int k = 1; k < 4; ++k) {
      if (std::abs(Depth(k, t)) < std::abs(Depth(best, t))) best = k;
    }
    return best;
  }
};

// The largest distance of the turned points from the nearest side.
double LargestResidual(const Rectangle& r, const std::vector<Eigen::Vector2d>& turned) {
  double largest = 0.0;
  for (const Eigen::Vector2d& t : turned) largest = std::max(largest, std::abs(r.Depth(r.NearestSide(t), t)));
  return largest;
}

// The rectangle the points lie on best: the orientation (in 0.1-degree
// steps over a quarter turn) whose bounding box leaves the least largest
// residual, then each side crossed clear of its corners moved to the mean
// of the points nearest it. A side with no point farther than
// `corner_margin` from both its ends is not `held`: a point at a corner
// lies on both sides, and a side it alone holds could lie anywhere
// (held_vase seed 1: a patch's bottom side, never crossed, drawn 4 mm short
// through a crossing of its left side); it stays at the bounding box.
struct FittedRectangle {
  Rectangle r;
  std::array<bool, 4> held{};
};

FittedRectangle FitRectangle(const std::vector<Eigen::Vector2d>& points, double corner_margin) {
  constexpr int kSteps = 900;
  Rectangle best;
  double best_residual = std::numeric_limits<double>::infinity();
  std::vector<Eigen::Vector2d> turned(points.size());
  for (int step = 0; step < kSteps; ++step) {
    Rectangle r;
    r.angle = 0.5 * std::numbers::pi * step / kSteps;
    r.lo = Eigen::Vector2d::Constant(std::numeric_limits<double>::infinity());
    r.hi = -r.lo;
    for (std::size_t i = 0; i < points.size(); ++i) {
      turned[i] = r.Turned(points[i]);
      r.lo = r.lo.cwiseMin(turned[i]);
      r.hi = r.hi.cwiseMax(turned[i]);
    }
    const double residual = LargestResidual(r, turned);
    if (residual < best_residual) best_residual = residual, best = r;
  }
  std::array<double, 4> sum{};
  std::array<int, 4> count{};
  FittedRectangle fitted{best, {}};
  for (const Eigen::Vector2d& p : points) {
    const Eigen::Vector2d t = best.Turned(p);
    const int k = best.NearestSide(t);
    sum[k] += k < 2 ? t.x() : t.y();
    ++count[k];
    const auto [from, to] = best.Extent(k);
    const double along = Rectangle::Along(k, t);
    if (along - from > corner_margin && to - along > corner_margin) fitted.held[k] = true;
  }
  if (fitted.held[0]) fitted.r.lo.x() = sum[0] / count[0];
  if (fitted.held[1]) fitted.r.hi.x() = sum[1] / count[1];
  if (fitted.held[2]) fitted.r.lo.y() = sum[2] / count[2];
  if (fitted.held[3]) fitted.r.hi.y() = sum[3] / count[3];
  return fitted;
}

// Calls fn(x, t) for every data point x near the rectangle (its turned
// plane coordinates t within `margin` of it, no farther off the plane than
// half its longer side: another part of the object is).
template <typename Fn>
void ForEachNear(const Plane& plane, const Rectangle& r, double margin, const LabelledPointGrid& data, const Fn& fn) {
  const Eigen::Vector2d size = r.hi - r.lo;
  const double reach = 0.5 * size.norm() + margin;
  const Eigen::Vector3d centre = plane.Point(r.Unturned(0.5 * (r.lo + r.hi)));
  const double max_off = 0.5 * size.maxCoeff();
  data.ForEachNear(centre, centre, reach + max_off, [&](const LabelledPoint& x) {
    if (std::abs(plane.Off(x.point)) > max_off) return;
    const Eigen::Vector2d t = r.Turned(plane.At(x.point));
    if (r.Depth(t) >= -margin) fn(x, t);
  });
}

// Whether data on the patch's sheet contradict the whole rectangle: another
// region inside it, or its own region outside it, beyond corridor_mm (out
// to half its shorter side more).
bool AreaContradicted(const Plane& plane, const Rectangle& r, int inner, const LabelledPointGrid& data,
                      const BoundaryLinkOptions& o) {
  const double ring = 0.5 * (r.hi - r.lo).minCoeff();
  bool contradicted = false;
  ForEachNear(plane, r, o.corridor_mm + ring, data, [&](const LabelledPoint& x, const Eigen::Vector2d& t) {
    if (!plane.OnSheet(x.point)) return;
    const double depth = r.Depth(t);
    if ((depth > o.corridor_mm && x.label != inner) || (depth < -o.corridor_mm && x.label == inner)) {
      contradicted = true;
    }
  });
  return contradicted;
}

// Whether other regions' data just outside side k (within corridor_mm of
// it) run along at least half its length, leaving no gap longer than half
// of it: a side no drag crossed clear of its corners, held in place by the
// data beyond it, as a one-sided dot's gap is closed (boundary_dots.h).
// No scored job has needed it yet: it changed no score on 190 in-process
// jobs (docs/method.md, "A rectangle checked only by data on its own
// sheet"); a reading of stored fits that suggested it (scan_handle_m's
// label, service seed 2) did not hold for the map's own crossings.
bool SideClosedByData(const Plane& plane, const Rectangle& r, int k, int inner, const LabelledPointGrid& data,
                      const BoundaryLinkOptions& o) {
  const auto [from, to] = r.Extent(k);
  std::vector<double> along = {from, to};
  ForEachNear(plane, r, o.corridor_mm, data, [&](const LabelledPoint& x, const Eigen::Vector2d& t) {
    const double depth = r.Depth(k, t), a = Rectangle::Along(k, t);
    if (x.label != inner && depth < 0.0 && depth >= -o.corridor_mm && a > from && a < to) along.push_back(a);
  });
  std::sort(along.begin(), along.end());
  double widest = 0.0;
  for (std::size_t i = 1; i < along.size(); ++i) widest = std::max(widest, along[i] - along[i - 1]);
  return widest < 0.5 * (to - from);
}

// The rectangle's sides as chords of at most max_dot_chord_mm, each with its
// outer region (that of the nearest data beyond it, else of the nearest
// crossing) and whether data near it lie more than max_dot_data_offset_mm
// on its wrong side.
struct Chord {
  int side = 0;
  double from = 0.0, to = 0.0;  // along the side
  int outer = -1;
  bool contradicted = false;
};

std::vector<Chord> SideChords(const Plane& plane, const Rectangle& r, int inner, const std::vector<ChangeMark>& marks,
                              const std::vector<int>& group, const LabelledPointGrid& data,
                              const BoundaryLinkOptions& o) {
  std::vector<Chord> chords;
  for (int k = 0; k < 4; ++k) {
    const auto [from, to] = r.Extent(k);
    const int steps = std::max(1, static_cast<int>(std::ceil((to - from) / o.max_dot_chord_mm)));
    for (int s = 0; s < steps; ++s) {
      chords.push_back({k, from + (to - from) * s / steps, from + (to - from) * (s + 1) / steps});
    }
  }
  std::vector<double> nearest(chords.size(), std::numeric_limits<double>::infinity());
  const double reach = (r.hi - r.lo).maxCoeff();
  ForEachNear(plane, r, reach, data, [&](const LabelledPoint& x, const Eigen::Vector2d& t) {
    for (std::size_t c = 0; c < chords.size(); ++c) {
      Chord& chord = chords[c];
      const double depth = r.Depth(chord.side, t), along = Rectangle::Along(chord.side, t);
      const Eigen::Vector2d middle = r.OnSide(chord.side, 0.5 * (chord.from + chord.to));
      if (x.label != inner && depth < 0.0 && (t - middle).norm() < nearest[c]) {
        nearest[c] = (t - middle).norm();
        chord.outer = x.label;
      }
      if (along < chord.from || along > chord.to || std::abs(depth) > o.corridor_mm) continue;
      if ((x.label == inner && depth < -o.max_dot_data_offset_mm) ||
          (x.label != inner && depth > o.max_dot_data_offset_mm)) {
        chord.contradicted = true;
      }
    }
  });
  for (Chord& chord : chords) {
    if (chord.outer >= 0) continue;
    const Eigen::Vector3d middle = plane.Point(r.Unturned(r.OnSide(chord.side, 0.5 * (chord.from + chord.to))));
    double best = std::numeric_limits<double>::infinity();
    for (int m : group) {
      const double d = (marks[m].position - middle).norm();
      if (d < best) best = d, chord.outer = OtherRegion(marks[m], inner);
    }
  }
  return chords;
}

// The rectangle of `inner` through the group's crossings, if they and the
// data make one (boundary_rectangles.h).
std::optional<BoundaryOutline> RectangleOf(const std::vector<ChangeMark>& marks, const std::vector<int>& group,
                                           int inner, const LabelledPointGrid& data, const BoundaryLinkOptions& o) {
  const std::optional<Plane> plane = PlaneOf(marks, group, o);
  if (!plane) return std::nullopt;
  std::vector<Eigen::Vector2d> points;
  for (int m : group) points.push_back(plane->At(marks[m].position));
  const FittedRectangle fitted = FitRectangle(points, o.corridor_mm);
  const Rectangle* r = &fitted.r;
  const Eigen::Vector2d size = r->hi - r->lo;
  if (size.minCoeff() < 2.0 * o.corridor_mm || size.maxCoeff() > o.max_rectangle_side_mm) return std::nullopt;
  for (int m : group) {
    const Eigen::Vector2d t = r->Turned(plane->At(marks[m].position));
    const int k = r->NearestSide(t);
    if (std::abs(r->Depth(k, t)) > o.max_dot_residual_mm) return std::nullopt;
    const Eigen::Vector3d in = TowardsA(marks[m], inner);
    const Eigen::Vector2d in_turned = r->Turned({in.dot(plane->e1), in.dot(plane->e2)});
    if (!(in_turned.dot(Rectangle::Inwards(k)) > 0.0)) return std::nullopt;  // it did not enter across this side
  }
  for (int k = 0; k < 4; ++k) {
    if (!fitted.held[k] && !(o.rectangle_sides_closed_by_data && SideClosedByData(*plane, *r, k, inner, data, o))) {
      return std::nullopt;
    }
  }
  if (AreaContradicted(*plane, *r, inner, data, o)) return std::nullopt;
  const std::vector<Chord> chords = SideChords(*plane, *r, inner, marks, group, data, o);
  std::vector<BoundarySegment> segments;
  std::vector<bool> contradicted;
  std::map<int, int> outers;
  for (const Chord& c : chords) {
    const Eigen::Vector3d p = plane->Point(r->Unturned(r->OnSide(c.side, c.from)));
    const Eigen::Vector3d q = plane->Point(r->Unturned(r->OnSide(c.side, c.to)));
    const Eigen::Vector3d inwards = plane->Vector(r->Unturned(Rectangle::Inwards(c.side)));
    segments.push_back({p, q, inwards, inner, c.outer, Eigen::Vector3d::Zero()});
    contradicted.push_back(c.contradicted);
    ++outers[c.outer];
  }
  std::optional<std::vector<BoundarySegment>> kept = UncontradictedChords(std::move(segments), contradicted, o);
  if (!kept) return std::nullopt;
  const int outer = std::max_element(outers.begin(), outers.end(), [](const auto& x, const auto& y) {
                      return x.second < y.second;
                    })->first;
  return BoundaryOutline{group, inner, outer, std::move(*kept), plane->normal};
}

}  // namespace

std::vector<BoundaryOutline> FindRectangles(const std::vector<ChangeMark>& marks, const LabelledPointGrid& data,
                                            const BoundaryLinkOptions& o, const std::set<int>& taken) {
  std::vector<BoundaryOutline> out;
  if (!(o.max_rectangle_side_mm > 0.0)) return out;
  for (const auto& [inner, members] : MarksByRegion(marks)) {
    for (const std::vector<int>& group : GroupMarks(marks, members, o.max_rectangle_side_mm)) {
      if (static_cast<int>(group.size()) < o.min_rectangle_crossings) continue;
      if (std::any_of(group.begin(), group.end(), [&](int m) { return taken.contains(m); })) continue;
      std::optional<BoundaryOutline> rectangle = RectangleOf(marks, group, inner, data, o);
      if (rectangle) out.push_back(std::move(*rectangle));
    }
  }
  return out;
}

}  // namespace surfmap
