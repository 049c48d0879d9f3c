// A rig's registration to an object: where the object sits in the rig's base
// frame, how big the probe's tip is, and how the force/torque sensor is
// turned against the base. What a real rig needs to turn the service's
// commands (in the object's frame: the mesh's) into motions, and what the
// service needs to read a trace the rig recorded in its own frame.
//
// Conventions (docs/trace-format.md, "Frames"):
//   p_base = R * p_object + t      R = object_rotation (unit quaternion), t in mm
//   f_base = S * f_sensor          S = sensor_rotation (unit quaternion)
//   tool centre = contact point + tip_radius_mm * outward surface normal
// Commands and traces refer to the CONTACT point on the object in every
// frame; the tool-centre path is given in addition, for rigs that servo the
// tool centre. The sensor's rotation is fixed: the probe is assumed to keep
// its orientation during a drag (a wrist that turns the sensor mid-drag must
// send forces in the base frame).
#pragma once

#include <array>
#include <string>
#include <string_view>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "absl/status/statusor.h"

namespace surfmap {

struct RigRegistration {
  Eigen::Quaterniond object_rotation = Eigen::Quaterniond::Identity();  // unit
  Eigen::Vector3d object_translation_mm = Eigen::Vector3d::Zero();
  double tip_radius_mm = 0.0;
  Eigen::Quaterniond sensor_rotation = Eigen::Quaterniond::Identity();  // unit
};

// Limits a lab's rig fits in: a tip is a ball of at most kMaxTipRadiusMm; the
// object within kMaxTranslationMm of the rig's base origin.
inline constexpr double kMaxTipRadiusMm = 50.0;
inline constexpr double kMaxTranslationMm = 10'000.0;
// How far |q| may be from 1 (a quaternion written with 6-7 digits, or from a
// rotation matrix in single precision, is within it); it is then normalised.
inline constexpr double kUnitQuaternionTolerance = 1e-5;

// Checks and builds a registration from raw numbers (quaternions as w, x, y,
// z). INVALID_ARGUMENT naming the field: a value not finite, a quaternion
// whose norm is not 1 (within kUnitQuaternionTolerance), a translation beyond
// kMaxTranslationMm, a tip radius outside [0, kMaxTipRadiusMm].
absl::StatusOr<RigRegistration> MakeRigRegistration(const std::array<double, 4>& object_rotation_wxyz,
                                                    const Eigen::Vector3d& object_translation_mm,
                                                    double tip_radius_mm,
                                                    const std::array<double, 4>& sensor_rotation_wxyz);

// The stored form: {"object_rotation_wxyz": [..4], "object_translation_mm":
// [..3], "tip_radius_mm": r, "sensor_rotation_wxyz": [..4]}, numbers written
// to round-trip exactly. The reader validates like MakeRigRegistration.
std::string RigRegistrationToJson(const RigRegistration& registration);
absl::StatusOr<RigRegistration> RigRegistrationFromJson(std::string_view json);

std::array<double, 4> QuaternionWxyz(const Eigen::Quaterniond& q);

}  // namespace surfmap
