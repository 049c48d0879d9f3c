// Distance from a point to a line segment: the planner's corridor and
// boundary-following tests both ask it of a drag's data window.
#pragma once

#include <Eigen/Core>

namespace surfmap {

// |p - q| for q the point of segment [a, b] nearest p; |p - a| when a == b.
double DistanceToSegment(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b);

}  // namespace surfmap
