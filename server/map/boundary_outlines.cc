#include "server/map/boundary_outlines.h"

#include <cmath>
#include <map>
#include <numbers>
#include <utility>

namespace surfmap {

std::optional<MarksPlane> PlaneOfMarks(const std::vector<ChangeMark>& marks, const std::vector<int>& group,
                                       const BoundaryLinkOptions& o) {
  MarksPlane plane;
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
  plane.origin.setZero();
  for (int m : group) normal += marks[m].normal, plane.origin += marks[m].position;
  if (!(normal.norm() > 1e-9)) return std::nullopt;
  plane.normal = normal.normalized();
  plane.origin /= static_cast<double>(group.size());
  const double min_cos = std::cos(o.max_corner_normal_deg * std::numbers::pi / 180.0);
  for (int m : group) {
    if (marks[m].normal.dot(plane.normal) < min_cos) return std::nullopt;
  }
  plane.e1 = InPlane(plane.normal.unitOrthogonal(), plane.normal).normalized();
  plane.e2 = plane.normal.cross(plane.e1);
  return plane;
}

std::vector<std::vector<int>> GroupMarks(const std::vector<ChangeMark>& marks, const std::vector<int>& members,
                                         double reach) {
  const int n = static_cast<int>(members.size());
  std::vector<int> group(n, -1);
  std::vector<std::vector<int>> out;
  for (int s = 0; s < n; ++s) {
    if (group[s] >= 0) continue;
    group[s] = static_cast<int>(out.size());
    out.push_back({members[s]});
    for (std::size_t k = 0; k < out.back().size(); ++k) {
      const Eigen::Vector3d& p = marks[out.back()[k]].position;
      for (int t = 0; t < n; ++t) {
        if (group[t] < 0 && (marks[members[t]].position - p).norm() <= reach) {
          group[t] = group[s];
          out.back().push_back(members[t]);
        }
      }
    }
  }
  return out;
}

std::vector<std::pair<int, std::vector<int>>> MarksByRegion(const std::vector<ChangeMark>& marks) {
  std::map<int, std::vector<int>> by_region;
  for (int m = 0; m < static_cast<int>(marks.size()); ++m) {
    if (marks[m].before == marks[m].after || marks[m].before < 0 || marks[m].after < 0) continue;
    by_region[marks[m].before].push_back(m);
    by_region[marks[m].after].push_back(m);
  }
  return {by_region.begin(), by_region.end()};
}

std::optional<std::vector<BoundarySegment>> UncontradictedChords(std::vector<BoundarySegment> chords,
                                                                 const std::vector<bool>& contradicted,
                                                                 const BoundaryLinkOptions& o) {
  std::vector<BoundarySegment> kept;
  for (std::size_t k = 0; k < chords.size(); ++k) {
    if (!contradicted[k]) kept.push_back(std::move(chords[k]));
  }
  const double left_out = static_cast<double>(chords.size() - kept.size());
  if (left_out > o.max_dot_contradicted_chord_share * static_cast<double>(chords.size())) return std::nullopt;
  return kept;
}

}  // namespace surfmap
