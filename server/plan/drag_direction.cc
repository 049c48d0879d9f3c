#include "server/plan/drag_direction.h"

#include <cmath>
#include <numbers>

#include <Eigen/Geometry>

namespace surfmap {

Eigen::Vector3d TangentDragDirection(const Eigen::Vector3d& normal) {
  const Eigen::Vector3d n = normal.normalized();
  int axis = 0;
  for (int i = 1; i < 3; ++i) {
    if (std::abs(n[i]) < std::abs(n[axis])) axis = i;
  }
  const Eigen::Vector3d e = Eigen::Vector3d::Unit(axis);
  return (e - e.dot(n) * n).normalized();
}

Eigen::Vector3d VariedDragDirection(const Eigen::Vector3d& normal, std::uint64_t key) {
  const Eigen::Vector3d n = normal.normalized();
  const Eigen::Vector3d t = TangentDragDirection(n);
  const double angle = static_cast<double>(key % 3) * std::numbers::pi / 3.0;
  return (std::cos(angle) * t + std::sin(angle) * n.cross(t)).normalized();
}

std::array<Eigen::Vector3d, 3> VariedDragDirections(const Eigen::Vector3d& normal, std::uint64_t key) {
  const std::uint64_t k = key % 3;
  return {VariedDragDirection(normal, k), VariedDragDirection(normal, k + 1), VariedDragDirection(normal, k + 2)};
}

}  // namespace surfmap
