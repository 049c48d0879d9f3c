#include "server/map/boundary_lines.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <tuple>
#include <utility>

#include <Eigen/Geometry>

namespace surfmap {
namespace {

double Radians(double degrees) { return degrees * std::numbers::pi / 180.0; }

// The link p -> q if the drags of both crossed its chord steeply enough
// with region `a` on the same side; false otherwise.
bool CrossedLink(const ChangeMark& p, const ChangeMark& q, int i, int j, int a, int b, double min_cos,
                 DrawnLink* out) {
  const std::optional<Eigen::Vector3d> towards_a = AcrossChordTowardsA(p, q, a, min_cos);
  if (!towards_a) return false;
  *out = {i, j, a, b, *towards_a};
  return true;
}

struct Line {
  double turn = 0.0;    // radians at the middle mark
  double length = 0.0;  // |PQ| + |QR|
  DrawnLink first;      // P -> Q
  DrawnLink second;     // R -> Q
};

// The links at mark m that hold the side of m towards position `to` (a new
// link there would be a second on that side), as indices into `links`.
std::vector<int> SideHolders(const std::vector<ChangeMark>& marks, const std::vector<DrawnLink>& links, int m,
                             const Eigen::Vector3d& to) {
  const Eigen::Vector3d way = to - marks[m].position;
  std::vector<int> holders;
  for (int k = 0; k < static_cast<int>(links.size()); ++k) {
    const DrawnLink& l = links[k];
    if (l.from != m && l.to != m) continue;
    const int other = l.from == m ? l.to : l.from;
    if ((marks[other].position - marks[m].position).dot(way) > 0.0) holders.push_back(k);
  }
  return holders;
}

int LinksAt(const std::vector<DrawnLink>& links, int m) {
  return static_cast<int>(std::count_if(links.begin(), links.end(), [m](const DrawnLink& l) {
    return l.from == m || l.to == m;
  }));
}

// Whether links[k], held at mark m, hangs there: its far mark has no other
// link, it runs off the chord m -> `to` by at least
// min_hanging_link_angle_deg (BoundaryLinkOptions; 90: never), and no other
// link at m runs straight on from it (turning by less than
// min_corner_turn_deg: the two are one boundary through m, crossed across
// the line; held_decals seed 16 lost a side of its L so).
bool Hanging(const std::vector<ChangeMark>& marks, const std::vector<DrawnLink>& links, int k, int m,
             const Eigen::Vector3d& to, const BoundaryLinkOptions& o) {
  const Eigen::Vector3d& n = marks[m].normal;
  auto away = [&](const DrawnLink& l) -> Eigen::Vector3d {
    const Eigen::Vector3d d = InPlane(marks[l.from == m ? l.to : l.from].position - marks[m].position, n);
    return d.norm() < 1e-9 ? Eigen::Vector3d::Zero() : Eigen::Vector3d(d.normalized());
  };
  if (!(o.min_hanging_link_angle_deg < 90.0)) return false;
  const DrawnLink& held = links[k];
  if (LinksAt(links, held.from == m ? held.to : held.from) != 1) return false;
  const Eigen::Vector3d h = away(held);
  const Eigen::Vector3d chord = InPlane(to - marks[m].position, n);
  if (h.isZero() || chord.norm() < 1e-9) return false;
  if (h.dot(chord.normalized()) > std::cos(Radians(o.min_hanging_link_angle_deg))) return false;
  const double straight_on = std::cos(Radians(o.min_corner_turn_deg));
  for (int j = 0; j < static_cast<int>(links.size()); ++j) {
    if (j == k || (links[j].from != m && links[j].to != m)) continue;
    if ((-away(links[j])).dot(h) > straight_on) return false;
  }
  return true;
}

bool Drawn(const std::vector<DrawnLink>& links, int i, int j) {
  return std::any_of(links.begin(), links.end(), [&](const DrawnLink& l) {
    return (l.from == i && l.to == j) || (l.from == j && l.to == i);
  });
}

}  // namespace

std::vector<DrawnLink> DrawLines(const std::vector<ChangeMark>& marks, std::vector<DrawnLink> links,
                                 const LabelledPointGrid& data, const BoundaryLinkOptions& o) {
  if (!(o.max_line_turn_deg > 0.0)) return links;
  const int n = static_cast<int>(marks.size());
  const double min_normal_cos = std::cos(Radians(o.max_corner_normal_deg));
  const double min_turn_cos = std::cos(Radians(o.max_line_turn_deg));
  const double line_crossing_cos = std::cos(Radians(o.max_line_crossing_deg));
  std::vector<Line> lines;
  for (int q = 0; q < n; ++q) {
    const ChangeMark& mq = marks[q];
    const int a = std::min(mq.before, mq.after), b = std::max(mq.before, mq.after);
    if (a == b) continue;
    // The marks that could be an outer end of a line through q, with their
    // distance from it.
    std::vector<std::pair<int, double>> near;
    for (int p = 0; p < n; ++p) {
      const ChangeMark& mp = marks[p];
      if (p == q || mp.drag == mq.drag || std::min(mp.before, mp.after) != a || std::max(mp.before, mp.after) != b) {
        continue;
      }
      const double d = (mp.position - mq.position).norm();
      if (d < std::min(o.min_line_chord_mm, o.min_corner_link_mm) || d > o.max_length_mm ||
          mp.normal.dot(mq.normal) < min_normal_cos) {
        continue;
      }
      near.emplace_back(p, d);
    }
    for (std::size_t x = 0; x < near.size(); ++x) {
      for (std::size_t y = x + 1; y < near.size(); ++y) {
        const auto [p, pq] = near[x];
        const auto [r, qr] = near[y];
        if (marks[p].drag == marks[r].drag) continue;
        // Short chords only inside a line whose ends are a corner link apart.
        if (std::min(pq, qr) < o.min_corner_link_mm &&
            (marks[r].position - marks[p].position).norm() < o.min_corner_link_mm) {
          continue;
        }
        const Eigen::Vector3d in = InPlane(mq.position - marks[p].position, mq.normal);
        const Eigen::Vector3d on = InPlane(marks[r].position - mq.position, mq.normal);
        if (in.norm() < 1e-9 || on.norm() < 1e-9) continue;
        const double turn_cos = in.normalized().dot(on.normalized());
        if (turn_cos < min_turn_cos) continue;  // also rejects P and R on the same side of Q
        Line line;
        if (!CrossedLink(marks[p], mq, p, q, a, b, line_crossing_cos, &line.first) ||
            !CrossedLink(marks[r], mq, r, q, a, b, line_crossing_cos, &line.second) ||
            line.first.towards_a.dot(line.second.towards_a) <= 0.0) {
          continue;
        }
        line.turn = std::acos(std::clamp(turn_cos, -1.0, 1.0));
        line.length = (mq.position - marks[p].position).norm() + (marks[r].position - mq.position).norm();
        lines.push_back(line);
      }
    }
  }
  std::sort(lines.begin(), lines.end(), [](const Line& l, const Line& r) {
    return std::tie(l.turn, l.length, l.first.from, l.first.to, l.second.from) <
           std::tie(r.turn, r.length, r.first.from, r.first.to, r.second.from);
  });
  for (const Line& line : lines) {
    std::vector<DrawnLink> added;
    std::vector<int> displaced;  // indices into links
    bool blocked = false;
    for (const DrawnLink& link : {line.first, line.second}) {
      if (Drawn(links, link.from, link.to)) continue;
      const ChangeMark& outer = marks[link.from];
      const ChangeMark& middle = marks[link.to];
      for (const auto& [m, to] : {std::pair{link.from, middle.position}, std::pair{link.to, outer.position}}) {
        for (int k : SideHolders(marks, links, m, to)) {
          if (!Hanging(marks, links, k, m, to, o)) blocked = true;
          displaced.push_back(k);
        }
      }
      if (blocked) break;
      const BoundarySegment segment{outer.position, middle.position, link.towards_a, link.a, link.b,
                                    ChordBow(outer.position, middle.position, outer.normal, middle.normal)};
      if (SegmentContradicted(segment, data, o)) {
        blocked = true;
        break;
      }
      added.push_back(link);
    }
    if (blocked) continue;
    std::sort(displaced.begin(), displaced.end());
    displaced.erase(std::unique(displaced.begin(), displaced.end()), displaced.end());
    for (auto k = displaced.rbegin(); k != displaced.rend(); ++k) links.erase(links.begin() + *k);
    links.insert(links.end(), added.begin(), added.end());
  }
  return links;
}

}  // namespace surfmap
