// The deterministic drag direction of a probe command.
#pragma once

#include <Eigen/Core>

namespace surfmap {

// The world axis least aligned with `normal` (ties go to x, then y), projected
// onto the tangent plane and normalised: the same rule as
// LoopSurface::DefaultDragDirection, computed from the normal alone so the
// planner needs no surface queries. `normal` must be non-zero (it is
// normalised here).
Eigen::Vector3d TangentDragDirection(const Eigen::Vector3d& normal);

}  // namespace surfmap
