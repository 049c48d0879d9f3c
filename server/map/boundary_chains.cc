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
                                double min_link_mm) {
  std::vector<int> degree(marks.size(), 0), last(marks.size(), -1);
  for (int k = 0; k < static_cast<int>(links.size()); ++k) {
    for (int m : {links[k].from, links[k].to}) {
      ++degree[m];
      last[m] = k;
    }
  }
  std::vector<ChainEnd> ends;
  for (int m = 0; m < static_cast<int>(marks.size()); ++m) {
    if (degree[m] != 1) continue;
    const DrawnLink& link = links[last[m]];
    const int other = link.from == m ? link.to : link.from;
    const Eigen::Vector3d out = marks[m].position - marks[other].position;
    if (out.norm() < min_link_mm) continue;
    ends.push_back({m, out.normalized(), link.towards_a, link.a, link.b});
  }
  return ends;
}

}  // namespace surfmap
