#include "server/plan/drag_direction.h"

#include <cmath>

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

}  // namespace surfmap
