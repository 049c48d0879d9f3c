#include "server/plan/boundary_selection.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>

namespace surfmap {

BoundarySelector::BoundarySelector(const SurfaceLevel& level, double reach_mm)
    : level_(&level), reach_mm_(reach_mm) {
  const auto& x = level.limit_positions;
  area_.assign(x.size(), 0.0);
  for (const auto& t : level.triangles) {
    const double a = 0.5 * (x[t[1]] - x[t[0]]).cross(x[t[2]] - x[t[0]]).norm() / 3.0;
    for (int v : t) area_[v] += a;
  }
  lo_ = x.empty() ? Eigen::Vector3d::Zero() : x.front();
  Eigen::Vector3d hi = lo_;
  for (const auto& p : x) lo_ = lo_.cwiseMin(p), hi = hi.cwiseMax(p);
  dims_ = (((hi - lo_) / reach_mm_).array().floor().cast<int>() + 1).matrix();
  grid_.assign(static_cast<std::size_t>(dims_.x()) * dims_.y() * dims_.z(), {});
  for (int v = 0; v < static_cast<int>(x.size()); ++v) {
    const Eigen::Vector3i c = ((x[v] - lo_) / reach_mm_).array().floor().cast<int>().matrix();
    grid_[(static_cast<std::size_t>(c.z()) * dims_.y() + c.y()) * dims_.x() + c.x()].push_back(v);
  }
}

template <typename Fn>
void BoundarySelector::ForEachWithin(const Eigen::Vector3d& centre, double radius, const Fn& fn) const {
  const auto& x = level_->limit_positions;
  const Eigen::Vector3i c = ((centre - lo_) / reach_mm_).array().floor().cast<int>().matrix();
  const int span = static_cast<int>(std::ceil(radius / reach_mm_));
  const double r2 = radius * radius;
  for (int z = std::max(0, c.z() - span); z <= std::min(dims_.z() - 1, c.z() + span); ++z) {
    for (int y = std::max(0, c.y() - span); y <= std::min(dims_.y() - 1, c.y() + span); ++y) {
      for (int xi = std::max(0, c.x() - span); xi <= std::min(dims_.x() - 1, c.x() + span); ++xi) {
        for (int v : grid_[(static_cast<std::size_t>(z) * dims_.y() + y) * dims_.x() + xi]) {
          if ((x[v] - centre).squaredNorm() <= r2) fn(v);
        }
      }
    }
  }
}

BoundarySelection BoundarySelector::Select(const RegionMap& map, std::span<const char> candidate,
                                           const std::vector<Eigen::Vector3d>& covered) const {
  BoundarySelection best;
  if (!map.has_pieces()) return best;
  const auto& x = level_->limit_positions;
  const int nv = static_cast<int>(x.size());
  // Removable variance per vertex, zero where an issued drag will measure.
  std::vector<double> boundary(nv), far(nv);
  for (int v = 0; v < nv; ++v) {
    boundary[v] = area_[v] * map.boundary_variance()[v];
    far[v] = area_[v] * map.far_variance()[v];
  }
  for (const Eigen::Vector3d& p : covered) {
    ForEachWithin(p, reach_mm_, [&](int v) { boundary[v] = far[v] = 0.0; });
  }
  const int candidates = std::min<int>(nv, static_cast<int>(candidate.size()));
  for (int c = 0; c < candidates; ++c) {
    if (!candidate[c]) continue;
    double b = 0.0, f = 0.0;
    ForEachWithin(x[c], reach_mm_, [&](int v) {
      b += boundary[v];
      f += far[v];
    });
    if (b + f > best.gain) {
      best.vertex = c;
      best.gain = b + f;
      best.boundary_share = b / (b + f);
    }
  }
  if (best.vertex < 0) return best;
  const Eigen::Vector3d& n = level_->limit_normals[best.vertex];
  if (best.boundary_share >= 0.5) {
    // Across the boundary where it is least known within the drag's reach.
    int most = -1;
    double most_b = 0.0;
    ForEachWithin(x[best.vertex], reach_mm_, [&](int v) {
      if (boundary[v] > most_b || (boundary[v] == most_b && most >= 0 && v < most)) {
        most_b = boundary[v];
        most = v;
      }
    });
    Eigen::Vector3d d = most >= 0 ? map.CrossingDirection(most) : Eigen::Vector3d::Zero();
    if (d.norm() < 0.5) d = map.CrossingDirection(best.vertex);
    d -= d.dot(n) * n;
    if (d.norm() > 1e-9) best.direction = d.normalized();
  } else {
    // Along the iso-distance line: perpendicular to the nearest data.
    const Eigen::Vector3d towards = map.NearestDataPoint(best.vertex) - x[best.vertex];
    Eigen::Vector3d d = n.cross(towards);
    d -= d.dot(n) * n;
    if (d.norm() > 1e-9) best.direction = d.normalized();
  }
  return best;
}

Eigen::Vector3d BoundarySelector::CrossingNear(const RegionMap& map, int v) const {
  if (!map.has_pieces() || v < 0 || v >= static_cast<int>(level_->limit_positions.size())) return Eigen::Vector3d::Zero();
  int most = -1;
  double most_b = 0.0;
  ForEachWithin(level_->limit_positions[v], reach_mm_, [&](int u) {
    const double b = area_[u] * map.boundary_variance()[u];
    if (b > most_b) {
      most_b = b;
      most = u;
    }
  });
  if (most < 0) return Eigen::Vector3d::Zero();
  const Eigen::Vector3d& n = level_->limit_normals[v];
  Eigen::Vector3d d = map.CrossingDirection(most);
  d -= d.dot(n) * n;
  return d.norm() > 1e-9 ? Eigen::Vector3d(d.normalized()) : Eigen::Vector3d::Zero();
}

}  // namespace surfmap
