// Which sites a rig can reach: set per job, so that the plan never issues a
// drag the robot cannot make (a probe cannot touch the underside of an
// object standing on a table, or a face turned away from its approach).
#pragma once

#include <optional>
#include <string>

#include <Eigen/Core>

namespace surfmap {

struct Reachability {
  // Unit vector from the object towards the probe (the probe moves along
  // -approach_direction to touch down); unset: every direction is reachable.
  std::optional<Eigen::Vector3d> approach_direction;
  // A site whose outward normal turns more than this from approach_direction
  // is out of reach. 100 degrees: a probe tilted a little can still drag on
  // faces slightly undercut from its approach.
  double max_angle_deg = 100.0;
  // The object rests on a support plane (a table): points of the object
  // within `support_clearance_mm` of the plane, on the side of
  // support_normal, cannot be reached by the probe's tip. Unset: no support.
  std::optional<Eigen::Vector3d> support_point;
  std::optional<Eigen::Vector3d> support_normal;  // unit, pointing away from the table, into the free space
  double support_clearance_mm = 5.0;  // the probe tip's radius plus a margin

  // False (and *why) for a zero or non-finite direction, an angle outside
  // (0, 180], a support point without a normal or the reverse, non-finite
  // values, a negative clearance.
  bool IsValid(std::string* why) const;
  bool constrained() const { return approach_direction.has_value() || support_point.has_value(); }
};

// Why a site at `position` with outward unit `normal` cannot be reached, or
// nothing when it can. The reason starts with "unreachable: " and says which
// limit is violated and by how much.
std::optional<std::string> UnreachableReason(const Reachability& reach, const Eigen::Vector3d& position,
                                             const Eigen::Vector3d& normal);

}  // namespace surfmap
