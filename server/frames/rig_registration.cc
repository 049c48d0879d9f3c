#include "server/frames/rig_registration.h"

#include <cmath>

#include <nlohmann/json.hpp>
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"

namespace surfmap {
namespace {

absl::StatusOr<Eigen::Quaterniond> UnitQuaternion(const char* field, const std::array<double, 4>& wxyz) {
  for (double v : wxyz) {
    if (!std::isfinite(v)) return absl::InvalidArgumentError(absl::StrCat(field, ": a component is not finite"));
  }
  const Eigen::Quaterniond q(wxyz[0], wxyz[1], wxyz[2], wxyz[3]);
  const double norm = q.norm();
  if (std::abs(norm - 1.0) > kUnitQuaternionTolerance) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "%s is not a unit quaternion: |(w, x, y, z)| = %.9g; a rotation needs w^2 + x^2 + y^2 + z^2 = 1 "
        "(within %g)",
        field, norm, kUnitQuaternionTolerance));
  }
  return q.normalized();
}

}  // namespace

std::array<double, 4> QuaternionWxyz(const Eigen::Quaterniond& q) { return {q.w(), q.x(), q.y(), q.z()}; }

absl::StatusOr<RigRegistration> MakeRigRegistration(const std::array<double, 4>& object_rotation_wxyz,
                                                    const Eigen::Vector3d& object_translation_mm,
                                                    double tip_radius_mm,
                                                    const std::array<double, 4>& sensor_rotation_wxyz) {
  RigRegistration r;
  absl::StatusOr<Eigen::Quaterniond> rotation = UnitQuaternion("object_pose.rotation", object_rotation_wxyz);
  if (!rotation.ok()) return rotation.status();
  r.object_rotation = *rotation;
  if (!object_translation_mm.allFinite()) {
    return absl::InvalidArgumentError("object_pose.translation_mm: a component is not finite");
  }
  if (object_translation_mm.norm() > kMaxTranslationMm) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "object_pose.translation_mm is %.6g mm from the rig's base origin; the limit is %.0f mm (a translation "
        "in metres or micrometres?)",
        object_translation_mm.norm(), kMaxTranslationMm));
  }
  r.object_translation_mm = object_translation_mm;
  if (!std::isfinite(tip_radius_mm) || tip_radius_mm < 0.0 || tip_radius_mm > kMaxTipRadiusMm) {
    return absl::InvalidArgumentError(absl::StrFormat("tip_radius_mm must be in [0, %.0f] mm, got %.6g",
                                                      kMaxTipRadiusMm, tip_radius_mm));
  }
  r.tip_radius_mm = tip_radius_mm;
  absl::StatusOr<Eigen::Quaterniond> sensor = UnitQuaternion("sensor_rotation", sensor_rotation_wxyz);
  if (!sensor.ok()) return sensor.status();
  r.sensor_rotation = *sensor;
  return r;
}

std::string RigRegistrationToJson(const RigRegistration& registration) {
  const Eigen::Vector3d& t = registration.object_translation_mm;
  nlohmann::json j = {{"object_rotation_wxyz", QuaternionWxyz(registration.object_rotation)},
                      {"object_translation_mm", {t.x(), t.y(), t.z()}},
                      {"tip_radius_mm", registration.tip_radius_mm},
                      {"sensor_rotation_wxyz", QuaternionWxyz(registration.sensor_rotation)}};
  return j.dump();  // nlohmann writes doubles that read back exactly
}

absl::StatusOr<RigRegistration> RigRegistrationFromJson(std::string_view text) {
  nlohmann::json j = nlohmann::json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (j.is_discarded() || !j.is_object()) return absl::InvalidArgumentError("rig registration: not a JSON object");
  auto numbers = [&](const char* key, size_t n, double* out) -> absl::Status {
    auto it = j.find(key);
    if (it == j.end() || !it->is_array() || it->size() != n) {
      return absl::InvalidArgumentError(absl::StrCat("rig registration: ", key, " must be an array of ", n,
                                                     " numbers"));
    }
    for (size_t i = 0; i < n; ++i) {
      if (!(*it)[i].is_number()) {
        return absl::InvalidArgumentError(absl::StrCat("rig registration: ", key, "[", i, "] is not a number"));
      }
      out[i] = (*it)[i].get<double>();
    }
    return absl::OkStatus();
  };
  std::array<double, 4> rotation{}, sensor{};
  double translation[3] = {0, 0, 0};
  double radius = 0;
  if (absl::Status s = numbers("object_rotation_wxyz", 4, rotation.data()); !s.ok()) return s;
  if (absl::Status s = numbers("object_translation_mm", 3, translation); !s.ok()) return s;
  auto r = j.find("tip_radius_mm");
  if (r == j.end() || !r->is_number()) return absl::InvalidArgumentError("rig registration: tip_radius_mm must be a number");
  radius = r->get<double>();
  if (absl::Status s = numbers("sensor_rotation_wxyz", 4, sensor.data()); !s.ok()) return s;
  return MakeRigRegistration(rotation, Eigen::Vector3d(translation[0], translation[1], translation[2]), radius,
                             sensor);
}

}  // namespace surfmap
