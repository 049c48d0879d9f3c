#include "server/map/boundary_corners.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <optional>
#include <tuple>

#include <Eigen/Dense>

namespace surfmap {
namespace {

struct Corner {
  double reach = 0.0;  // s + t
  int e1 = -1;
  int e2 = -1;
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  // the plane the corner is drawn in
  BoundarySegment first, second;                      // E1 -> C, C -> E2
  int inside = -1;                                    // the region the turn encloses
};

// The corner of ends x and y, if they make one.
std::optional<Corner> CornerOf(const ChangeMark& m1, const ChainEnd& x, const ChangeMark& m2, const ChainEnd& y,
                               const BoundaryLinkOptions& o) {
  if (x.a != y.a || x.b != y.b) return std::nullopt;
  // A corner is drawn straight in one tangent plane: two ends whose normals
  // differ by more than max_corner_normal_deg are not on one piece of
  // surface (the two faces of a thin object, or round a sharp edge).
  if (m1.normal.dot(m2.normal) < std::cos(o.max_corner_normal_deg * std::numbers::pi / 180.0)) return std::nullopt;
  const Eigen::Vector3d n = (m1.normal + m2.normal).normalized();
  const Eigen::Vector3d u1 = InPlane(x.out, n).normalized(), u2 = InPlane(y.out, n).normalized();
  // The boundary runs E1 -> C along u1, then C -> E2 along -u2.
  const double turn = std::acos(std::clamp(u1.dot(-u2), -1.0, 1.0)) * 180.0 / std::numbers::pi;
  if (turn < o.min_corner_turn_deg || turn > o.max_corner_turn_deg) return std::nullopt;
  Eigen::Matrix<double, 3, 2> lines;
  lines.col(0) = u1;
  lines.col(1) = -u2;
  const Eigen::Vector3d gap = InPlane(m2.position - m1.position, n);
  const Eigen::Vector2d st = lines.colPivHouseholderQr().solve(gap);
  const double s = st(0), t = st(1);
  if (!(s > 0.0 && t > 0.0 && s <= o.corner_reach_mm && t <= o.corner_reach_mm)) return std::nullopt;
  if ((lines * st - gap).norm() > o.corridor_mm) return std::nullopt;  // the two lines pass each other
  const Eigen::Vector3d ta1 = InPlane(x.towards_a, n).normalized(), ta2 = InPlane(y.towards_a, n).normalized();
  if (n.dot(u1.cross(ta1)) * n.dot((-u2).cross(ta2)) <= 0.0) return std::nullopt;  // a changes hands
  const Eigen::Vector3d c = 0.5 * ((m1.position + s * u1) + (m2.position + t * u2));
  Corner corner;
  corner.reach = s + t;
  corner.normal = n;
  // The corner's plane turns half-way between the ends' normals.
  corner.first = {m1.position, c, ta1, x.a, x.b, ChordBow(m1.position, c, m1.normal, n)};
  corner.second = {c, m2.position, ta2, x.a, x.b, ChordBow(c, m2.position, n, m2.normal)};
  corner.inside = gap.dot(ta1) > 0.0 ? x.a : x.b;
  return corner;
}

// True when a data point of another region than `corner.inside` lies in
// the triangle E1, C, E2 (farther than seed_offset_mm inside its sides).
bool TriangleContradicted(const Corner& corner, const LabelledPointGrid& data, const BoundaryLinkOptions& o) {
  const Eigen::Vector3d& n = corner.normal;
  const Eigen::Vector3d p0 = corner.first.p, p1 = corner.first.q, p2 = corner.second.q;
  const Eigen::Vector3d lo = p0.cwiseMin(p1).cwiseMin(p2), hi = p0.cwiseMax(p1).cwiseMax(p2);
  Eigen::Matrix<double, 3, 2> edges;
  edges.col(0) = InPlane(p1 - p0, n);
  edges.col(1) = InPlane(p2 - p0, n);
  const double area2 = edges.col(0).cross(edges.col(1)).norm();
  if (!(area2 > 1e-9)) return false;
  const Eigen::ColPivHouseholderQR<Eigen::Matrix<double, 3, 2>> barycentric(edges);  // once per triangle
  // Barycentric tolerance: seed_offset_mm over the triangle's smallest height.
  const double longest = std::max({(p1 - p0).norm(), (p2 - p1).norm(), (p0 - p2).norm()});
  const double margin = o.seed_offset_mm * longest / area2;
  // Points whose distance from the triangle's plane exceeds its size belong
  // to another sheet of the surface (the far side of a thin object).
  const double sheet = longest;
  bool contradicted = false;
  data.ForEachNear(lo, hi, o.seed_offset_mm, [&](const LabelledPoint& x) {
    if (contradicted || x.label == corner.inside) return;
    const Eigen::Vector3d r = x.point - p0;
    if (std::abs(r.dot(n)) > sheet) return;
    const Eigen::Vector2d uv = barycentric.solve(InPlane(r, n));
    if (uv(0) > margin && uv(1) > margin && uv(0) + uv(1) < 1.0 - margin) contradicted = true;
  });
  return contradicted;
}

// True when the marks `side` (walked from `end`) lie within
// max_corner_side_residual_mm of the line from `end` to the last of them.
bool RunsStraight(const std::vector<ChangeMark>& marks, int end, const Eigen::Vector3d& n, const std::vector<int>& side,
                  const BoundaryLinkOptions& o) {
  const Eigen::Vector3d line = InPlane(marks[side.back()].position - marks[end].position, n);
  if (line.norm() < o.min_corner_link_mm) return false;
  const Eigen::Vector3d u = line.normalized();
  for (int m : side) {
    const Eigen::Vector3d r = InPlane(marks[m].position - marks[end].position, n);
    if ((r - r.dot(u) * u).norm() > o.max_corner_side_residual_mm) return false;
  }
  return true;
}

// A side that runs straight over two links or more and then turns by a
// corner's angle (min_corner_turn_deg) within the reach: *side cut to its
// straight run, so a small patch's side is not refused for the next corner
// round the patch. Left as it is otherwise.
void TruncateAtNextCorner(const std::vector<ChangeMark>& marks, int end, const Eigen::Vector3d& n,
                          const BoundaryLinkOptions& o, std::vector<int>* side) {
  if (side->size() < 3 || RunsStraight(marks, end, n, *side, o)) return;
  for (std::size_t count = side->size() - 1; count >= 2; --count) {
    const std::vector<int> run(side->begin(), side->begin() + count);
    if (!RunsStraight(marks, end, n, run, o)) continue;
    const Eigen::Vector3d along = InPlane(marks[run.back()].position - marks[end].position, n).normalized();
    const Eigen::Vector3d next = InPlane(marks[(*side)[count]].position - marks[run.back()].position, n);
    if (next.norm() < 1e-9) return;
    const double turn = std::acos(std::clamp(along.dot(next.normalized()), -1.0, 1.0)) * 180.0 / std::numbers::pi;
    if (turn >= o.min_corner_turn_deg) *side = run;
    return;
  }
}

// The straight side of the chain at mark `end`, away from mark `away`:
// a ChainEnd pointing out of it towards `end`, or nullopt when the chain
// there has fewer than two links, branches, or turns by more than
// max_corner_side_residual_mm within corner_side_reach_mm of `end`. A side of
// one link is taken when the link after it, past the reach, runs on, or
// (with corner_side_may_end_its_chain) when the chain ends at it; then
// *chain_ends is set, and only the other side can show the corner is one.
std::optional<ChainEnd> StraightSide(const std::vector<ChangeMark>& marks, const std::vector<DrawnLink>& links,
                                     const std::vector<std::vector<int>>& links_of, int end, int away,
                                     const BoundaryLinkOptions& o, bool* chain_ends) {
  *chain_ends = false;
  const Eigen::Vector3d& n = marks[end].normal;
  std::vector<int> side;  // marks along the chain from `end`, within reach
  int beyond = -1;        // the mark after them, past the reach
  int first_link = -1;
  int prev = away, cur = end;
  bool ended = false;  // no link goes on from the last mark of `side`
  while (true) {
    int next = -1, via = -1;
    for (int k : links_of[cur]) {
      const int other = links[k].from == cur ? links[k].to : links[k].from;
      if (other == prev || (cur == end && other == away)) continue;
      if (next >= 0) return std::nullopt;  // the chain branches
      next = other;
      via = k;
    }
    if (next < 0) ended = true;
    if (next < 0 || next == end) break;
    if ((marks[next].position - marks[end].position).norm() > o.corner_side_reach_mm) {
      beyond = next;
      break;
    }
    if (std::find(side.begin(), side.end(), next) != side.end()) break;
    if (first_link < 0) first_link = via;
    side.push_back(next);
    prev = cur;
    cur = next;
  }
  if (side.empty()) return std::nullopt;
  if (o.corner_side_stops_at_next_corner) TruncateAtNextCorner(marks, end, n, o, &side);
  const Eigen::Vector3d line = InPlane(marks[side.back()].position - marks[end].position, n);
  if (line.norm() < o.min_corner_link_mm) return std::nullopt;
  const Eigen::Vector3d u = line.normalized();
  if (side.size() == 1) {
    // One link: straight only if the next one, past the reach, runs on, or
    // if there is none (two crossings are a line; whether the boundary
    // turns at them is left to the other side).
    if (beyond < 0) {
      if (!o.corner_side_may_end_its_chain || !ended) return std::nullopt;
      *chain_ends = true;
    } else {
      if (!o.corner_side_checked_past_reach) return std::nullopt;
      const Eigen::Vector3d on = InPlane(marks[beyond].position - marks[side.front()].position, n);
      if (on.norm() < o.min_corner_link_mm ||
          on.normalized().dot(u) < std::cos(o.max_line_turn_deg * std::numbers::pi / 180.0)) {
        return std::nullopt;
      }
    }
  }
  if (!RunsStraight(marks, end, n, side, o)) return std::nullopt;
  const DrawnLink& link = links[first_link];
  return ChainEnd{end, -u, link.towards_a, link.a, link.b};
}

// The end at mark `unknown` of a side whose direction the data do not show,
// taken square to the straight side `known` (at mark known.mark): out of
// `unknown` at right angles to known.out, towards the known side's line.
// Nullopt when the chord from the known end turns from its side by less
// than min_corner_turn_deg (the link runs on along the side: no corner is
// cut), or when the crossing's drag ran along the square direction (no side
// to tell region a's from).
std::optional<ChainEnd> SquareEnd(const std::vector<ChangeMark>& marks, int unknown, const ChainEnd& known,
                                  const BoundaryLinkOptions& o) {
  const ChangeMark& m = marks[unknown];
  const Eigen::Vector3d& n = m.normal;
  const Eigen::Vector3d chord = InPlane(m.position - marks[known.mark].position, n);
  if (chord.norm() < 1e-9 ||
      chord.normalized().dot(InPlane(known.out, n).normalized()) > std::cos(o.min_corner_turn_deg * std::numbers::pi / 180.0)) {
    return std::nullopt;
  }
  Eigen::Vector3d out = InPlane(n.cross(known.out), n);
  if (out.norm() < 1e-9) return std::nullopt;
  out.normalize();
  if (InPlane(marks[known.mark].position - m.position, n).dot(out) < 0.0) out = -out;
  // Region a's side across the square side, from the crossing drag: a drag
  // within ~15 degrees of the square direction (sin 15 ~ 0.25) shows none.
  constexpr double kMinAcrossShare = 0.25;
  Eigen::Vector3d towards_a = InPlane(TowardsA(m, known.a), n);
  towards_a -= towards_a.dot(out) * out;
  if (towards_a.norm() < kMinAcrossShare) return std::nullopt;
  return ChainEnd{unknown, out, towards_a.normalized(), known.a, known.b};
}

}  // namespace

std::vector<DrawnLink> ReplaceCutCorners(const std::vector<ChangeMark>& marks, std::vector<DrawnLink> links,
                                         const LabelledPointGrid& data, const BoundaryLinkOptions& o,
                                         std::vector<LabelledPoint>* points, int* count) {
  if (count != nullptr) *count = 0;
  if (!(o.max_corner_side_residual_mm > 0.0) || !(o.corner_reach_mm > 0.0) || !(o.corner_side_reach_mm > 0.0)) {
    return links;
  }
  std::vector<std::vector<int>> links_of(marks.size());
  for (int k = 0; k < static_cast<int>(links.size()); ++k) {
    links_of[links[k].from].push_back(k);
    links_of[links[k].to].push_back(k);
  }
  std::vector<std::pair<Corner, int>> candidates;  // with the link it replaces
  for (int k = 0; k < static_cast<int>(links.size()); ++k) {
    const DrawnLink& link = links[k];
    bool x_ends = false, y_ends = false;
    std::optional<ChainEnd> x = StraightSide(marks, links, links_of, link.from, link.to, o, &x_ends);
    std::optional<ChainEnd> y = StraightSide(marks, links, links_of, link.to, link.from, o, &y_ends);
    if (o.square_corner_from_one_side && x.has_value() != y.has_value()) {
      // One straight side of several crossings; the other's direction unknown.
      if (x ? x_ends : y_ends) continue;
      if (x) {
        y = SquareEnd(marks, link.to, *x, o);
      } else {
        x = SquareEnd(marks, link.from, *y, o);
      }
    }
    if (!x || !y || (x_ends && y_ends)) continue;  // two lone links show no straight side
    std::optional<Corner> c = CornerOf(marks[link.from], *x, marks[link.to], *y, o);
    if (c) candidates.emplace_back(*c, k);
  }
  std::sort(candidates.begin(), candidates.end(), [](const auto& l, const auto& r) {
    return std::tie(l.first.reach, l.second) < std::tie(r.first.reach, r.second);
  });
  std::vector<bool> used(marks.size(), false), replaced(links.size(), false);
  for (const auto& [c, k] : candidates) {
    if (used[links[k].from] || used[links[k].to]) continue;
    if (SegmentContradicted(c.first, data, o) || SegmentContradicted(c.second, data, o) ||
        TriangleContradicted(c, data, o)) {
      continue;
    }
    used[links[k].from] = used[links[k].to] = true;
    replaced[k] = true;
    AppendSegmentSeeds(c.first, o, points);
    AppendSegmentSeeds(c.second, o, points);
    if (count != nullptr) ++*count;
  }
  std::vector<DrawnLink> kept;
  for (int k = 0; k < static_cast<int>(links.size()); ++k) {
    if (!replaced[k]) kept.push_back(links[k]);
  }
  return kept;
}

std::vector<LabelledPoint> BoundaryCornerPoints(const std::vector<ChangeMark>& marks,
                                                const std::vector<DrawnLink>& links, const LabelledPointGrid& data,
                                                const BoundaryLinkOptions& o, int* corners) {
  std::vector<LabelledPoint> out;
  int drawn = 0;
  if (o.corner_reach_mm > 0.0) {
    const std::vector<ChainEnd> ends = ChainEnds(marks, links, o.min_corner_link_mm, o.chain_ends_reach_past_short_links);
    std::vector<Corner> candidates;
    for (int i = 0; i < static_cast<int>(ends.size()); ++i) {
      for (int j = i + 1; j < static_cast<int>(ends.size()); ++j) {
        std::optional<Corner> c = CornerOf(marks[ends[i].mark], ends[i], marks[ends[j].mark], ends[j], o);
        if (!c) continue;
        c->e1 = i;
        c->e2 = j;
        candidates.push_back(*c);
      }
    }
    std::sort(candidates.begin(), candidates.end(), [](const Corner& l, const Corner& r) {
      return std::tie(l.reach, l.e1, l.e2) < std::tie(r.reach, r.e1, r.e2);
    });
    std::vector<bool> used(ends.size(), false);
    for (const Corner& c : candidates) {
      if (used[c.e1] || used[c.e2]) continue;
      if (SegmentContradicted(c.first, data, o) || SegmentContradicted(c.second, data, o) ||
          TriangleContradicted(c, data, o)) {
        continue;
      }
      used[c.e1] = used[c.e2] = true;
      ++drawn;
      AppendSegmentSeeds(c.first, o, &out);
      AppendSegmentSeeds(c.second, o, &out);
    }
  }
  if (corners != nullptr) *corners = drawn;
  return out;
}

}  // namespace surfmap
