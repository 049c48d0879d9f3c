#include "server/map/boundary_chains.h"

#include <cmath>

#include <Eigen/Geometry>

namespace surfmap {

std::optional<Eigen::Vector3d> AcrossChordTowardsA(const ChangeMark& p, const ChangeMark& q, int a, double min_cos) {
  const Eigen::Vector3d normal = (p.normal + q.normal).normalized();
  Eigen::Vector3d across = (q.position - p.position).cross(normal);
  if (across.norm() < 1e-9) return std::nullopt;
  across.normalize();
  const double sp = TowardsA(p, a).dot(across), sq = TowardsA(q, a).dot(across);
  if (sp * sq <= 0.0 || std::abs(sp) < min_cos || std::abs(sq) < min_cos) return std::nullopt;
  return sp > 0 ? across : Eigen::Vector3d(-across);
}

std::vector<ChainEnd> ChainEnds(const std::vector<ChangeMark>& marks, const std::vector<DrawnLink>& links,
                                double min_link_mm, bool reach_past_short_links) {
  std::vector<std::vector<int>> links_of(marks.size());
  for (int k = 0; k < static_cast<int>(links.size()); ++k) {
    for (int m : {links[k].from, links[k].to}) links_of[m].push_back(k);
  }
  auto other_end = [&](int k, int m) { return links[k].from == m ? links[k].to : links[k].from; };
  std::vector<ChainEnd> ends;
  for (int m = 0; m < static_cast<int>(marks.size()); ++m) {
    if (links_of[m].size() != 1) continue;
    const DrawnLink& link = links[links_of[m].front()];
    int prev = m, cur = other_end(links_of[m].front(), m);
    // Walk back while the mark reached is nearer than min_link_mm; each
    // step leaves a mark with two links by the one not yet taken.
    while (reach_past_short_links && (marks[cur].position - marks[m].position).norm() < min_link_mm &&
           links_of[cur].size() == 2) {
      const int k = other_end(links_of[cur][0], cur) == prev ? links_of[cur][1] : links_of[cur][0];
      prev = cur;
      cur = other_end(k, cur);
    }
    const Eigen::Vector3d out = marks[m].position - marks[cur].position;
    if (out.norm() < min_link_mm) continue;
    ends.push_back({m, out.normalized(), link.towards_a, link.a, link.b});
  }
  return ends;
}

}  // namespace surfmap
