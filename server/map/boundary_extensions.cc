#include "server/map/boundary_extensions.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <tuple>

#include <Eigen/Geometry>

namespace surfmap {
namespace {

double Degrees(double radians) { return radians * 180.0 / std::numbers::pi; }

// The extension of chain end `end` to marks[q], if it makes one.
bool Extends(const std::vector<ChangeMark>& marks, const ChainEnd& end, int q, const BoundaryLinkOptions& o,
             DrawnLink* out) {
  const ChangeMark& e = marks[end.mark];
  const ChangeMark& m = marks[q];
  if (m.drag == e.drag || std::min(m.before, m.after) != end.a || std::max(m.before, m.after) != end.b) return false;
  if (e.normal.dot(m.normal) < std::cos(o.max_corner_normal_deg * std::numbers::pi / 180.0)) return false;
  const Eigen::Vector3d chord = m.position - e.position;
  const double length = chord.norm();
  if (!(length > 1e-9) || length > o.max_extension_length_mm) return false;
  const Eigen::Vector3d along = InPlane(chord, e.normal);
  const Eigen::Vector3d out_dir = InPlane(end.out, e.normal);
  if (along.norm() < 1e-9 || out_dir.norm() < 1e-9) return false;
  const double turn = Degrees(std::acos(std::clamp(along.normalized().dot(out_dir.normalized()), -1.0, 1.0)));
  if (turn > o.max_extension_turn_deg) return false;
  const Eigen::Vector3d normal = (e.normal + m.normal).normalized();
  Eigen::Vector3d across = chord.cross(normal);
  if (across.norm() < 1e-9) return false;
  across.normalize();
  const double at_end = end.towards_a.dot(across), at_q = TowardsA(m, end.a).dot(across);
  if (at_end * at_q <= 0.0 || std::abs(at_q) < o.min_extension_crossing_cos) return false;
  *out = {end.mark, q, end.a, end.b, at_q > 0 ? across : Eigen::Vector3d(-across)};
  return true;
}

}  // namespace

std::vector<DrawnLink> ExtendChains(const std::vector<ChangeMark>& marks, std::vector<DrawnLink> links,
                                    const LabelledPointGrid& data, const BoundaryLinkOptions& o) {
  if (!(o.max_extension_turn_deg > 0.0)) return links;
  const int n = static_cast<int>(marks.size());
  for (bool grew = true; grew;) {
    grew = false;
    std::vector<bool> linked(n, false);
    for (const DrawnLink& l : links) linked[l.from] = linked[l.to] = true;
    // Every end's nearest extension, nearest first; each crossing joins one.
    std::vector<std::pair<double, DrawnLink>> candidates;
    for (const ChainEnd& end : ChainEnds(marks, links, o.min_corner_link_mm, o.chain_ends_reach_past_short_links)) {
      double best = std::numeric_limits<double>::infinity();
      DrawnLink chosen;
      for (int q = 0; q < n; ++q) {
        DrawnLink link;
        if (linked[q] || !Extends(marks, end, q, o, &link)) continue;
        const double d = (marks[q].position - marks[end.mark].position).norm();
        if (d >= best) continue;
        const ChangeMark& e = marks[end.mark];
        const BoundarySegment segment{e.position, marks[q].position, link.towards_a, link.a, link.b,
                                      ChordBow(e.position, marks[q].position, e.normal, marks[q].normal)};
        if (SegmentContradicted(segment, data, o)) {
          continue;
        }
        best = d;
        chosen = link;
      }
      if (chosen.from >= 0) candidates.emplace_back(best, chosen);
    }
    std::sort(candidates.begin(), candidates.end(), [](const auto& l, const auto& r) {
      return std::tie(l.first, l.second.from, l.second.to) < std::tie(r.first, r.second.from, r.second.to);
    });
    for (const auto& [d, link] : candidates) {
      if (linked[link.to]) continue;
      linked[link.to] = true;
      links.push_back(link);
      grew = true;
    }
  }
  return links;
}

}  // namespace surfmap
