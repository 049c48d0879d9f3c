#include "server/plan/reachability.h"

#include <cmath>
#include <numbers>

#include "absl/strings/str_format.h"

namespace surfmap {

bool Reachability::IsValid(std::string* why) const {
  auto fail = [why](std::string m) {
    if (why != nullptr) *why = std::move(m);
    return false;
  };
  if (approach_direction && (!approach_direction->allFinite() || approach_direction->norm() < 1e-9)) {
    return fail("approach_direction must be a finite non-zero vector");
  }
  if (!(std::isfinite(max_angle_deg) && max_angle_deg > 0.0 && max_angle_deg <= 180.0)) {
    return fail(absl::StrFormat("max_angle_deg %g must be in (0, 180]", max_angle_deg));
  }
  if (support_point.has_value() != support_normal.has_value()) {
    return fail("a support plane needs both support_point and support_normal");
  }
  if (support_point && !support_point->allFinite()) return fail("support_point must be finite");
  if (support_normal && (!support_normal->allFinite() || support_normal->norm() < 1e-9)) {
    return fail("support_normal must be a finite non-zero vector");
  }
  if (!(std::isfinite(support_clearance_mm) && support_clearance_mm >= 0.0)) {
    return fail("support_clearance_mm must be >= 0");
  }
  return true;
}

std::optional<std::string> UnreachableReason(const Reachability& reach, const Eigen::Vector3d& position,
                                             const Eigen::Vector3d& normal) {
  if (reach.approach_direction) {
    const Eigen::Vector3d a = reach.approach_direction->normalized();
    const double angle = std::acos(std::clamp(a.dot(normal.normalized()), -1.0, 1.0)) * 180.0 / std::numbers::pi;
    if (angle > reach.max_angle_deg) {
      return absl::StrFormat("unreachable: the surface normal is %.1f deg from the approach direction (limit %.1f)",
                             angle, reach.max_angle_deg);
    }
  }
  if (reach.support_point) {
    const double height = (position - *reach.support_point).dot(reach.support_normal->normalized());
    if (height < reach.support_clearance_mm) {
      return absl::StrFormat("unreachable: %.1f mm above the support plane (the probe needs %.1f)", height,
                             reach.support_clearance_mm);
    }
  }
  return std::nullopt;
}

}  // namespace surfmap
