// The deterministic drag direction of a probe command.
#pragma once

#include <array>
#include <cstdint>

#include <Eigen/Core>

namespace surfmap {

// The world axis least aligned with `normal` (ties go to x, then y), projected
// onto the tangent plane and normalised: the same rule as
// LoopSurface::DefaultDragDirection, computed from the normal alone so the
// planner needs no surface queries. `normal` must be non-zero (it is
// normalised here).
Eigen::Vector3d TangentDragDirection(const Eigen::Vector3d& normal);

// TangentDragDirection turned about the normal by 0, 60 or 120 degrees, by
// `key` modulo 3 (e.g. a site's shuffle key): where nothing is known yet,
// neighbouring drags run in different directions, and a boundary of any
// direction is crossed at 60 degrees or more by a third of them (a drag that
// runs along a narrow band never finds it).
Eigen::Vector3d VariedDragDirection(const Eigen::Vector3d& normal, std::uint64_t key);

// The three directions VariedDragDirection takes at `normal`, the one `key`
// gives first, then the next two keys'.
std::array<Eigen::Vector3d, 3> VariedDragDirections(const Eigen::Vector3d& normal, std::uint64_t key);

}  // namespace surfmap
