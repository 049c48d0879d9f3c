#include "server/mesh/mesh_locator.h"

#include <cmath>

#include <Eigen/Geometry>
#include "server/mesh/triangle_bvh.h"

namespace surfmap {

// The tree points into the positions and triangles, so they live here, at a
// stable address, with it.
struct MeshLocator::Impl {
  std::vector<Eigen::Vector3d> positions;
  std::vector<std::array<int, 3>> triangles;
  TriangleBvh tree;
};

MeshLocator::MeshLocator(std::vector<Eigen::Vector3d> positions, std::vector<std::array<int, 3>> triangles)
    : impl_(std::make_unique<Impl>()) {
  impl_->positions = std::move(positions);
  impl_->triangles = std::move(triangles);
  impl_->tree = TriangleBvh(&impl_->positions, &impl_->triangles);
}

MeshLocator::MeshLocator(const SurfaceLevel& level) : MeshLocator(level.limit_positions, level.triangles) {}
MeshLocator::MeshLocator(MeshLocator&&) noexcept = default;
MeshLocator& MeshLocator::operator=(MeshLocator&&) noexcept = default;
MeshLocator::~MeshLocator() = default;

const std::vector<Eigen::Vector3d>& MeshLocator::positions() const { return impl_->positions; }
const std::vector<std::array<int, 3>>& MeshLocator::triangles() const { return impl_->triangles; }

SurfacePoint MeshLocator::ClosestAlong(const Eigen::Vector3d& point, const Eigen::Vector3d& direction) const {
  // Each step moves to the foot of the closest point on the line; on a
  // surface curving away from the line it converges linearly (by about a
  // half per step where the line meets a cylinder 0.8 radii off its axis).
  constexpr int kMaxSteps = 64;
  constexpr double kStepTolerance = 1e-4, kOffLine = 0.05;
  SurfacePoint hit;
  double t = 0.0;
  for (int step = 0; step < kMaxSteps; ++step) {
    hit = Closest(point + t * direction);
    if (hit.triangle < 0) return hit;
    const double next = (hit.position - point).dot(direction);
    const bool settled = std::abs(next - t) < kStepTolerance;
    t = next;
    if (settled) break;
  }
  if ((hit.position - (point + t * direction)).norm() > kOffLine) return SurfacePoint{};
  return hit;
}

SurfacePoint MeshLocator::Closest(const Eigen::Vector3d& query) const {
  SurfacePoint out;
  if (impl_->triangles.empty()) return out;
  const ClosestTriangle hit = impl_->tree.Closest(query);
  if (hit.triangle < 0) return out;
  const auto& t = impl_->triangles[hit.triangle];
  const auto& p = impl_->positions;
  out.triangle = hit.triangle;
  out.barycentric = hit.barycentric;
  out.position = hit.position;
  out.distance = std::sqrt(hit.squared_distance);
  const Eigen::Vector3d n = (p[t[1]] - p[t[0]]).cross(p[t[2]] - p[t[0]]);
  out.normal = n.norm() > 0 ? Eigen::Vector3d(n.normalized()) : Eigen::Vector3d::UnitZ();
  return out;
}

}  // namespace surfmap
