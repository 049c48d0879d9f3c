#include "server/plan/reachability_json.h"

#include <optional>
#include <string>

#include "absl/strings/str_cat.h"

namespace surfmap {
namespace {

nlohmann::json VectorOrNull(const std::optional<Eigen::Vector3d>& v) {
  if (!v) return nullptr;
  return {v->x(), v->y(), v->z()};
}

absl::Status ReadVector(const nlohmann::json& j, const char* key, std::optional<Eigen::Vector3d>& out) {
  auto it = j.find(key);
  if (it == j.end() || it->is_null()) return absl::OkStatus();
  if (!it->is_array() || it->size() != 3 || !(*it)[0].is_number() || !(*it)[1].is_number() ||
      !(*it)[2].is_number()) {
    return absl::InvalidArgumentError(absl::StrCat("reach.", key, " must be 3 numbers or null"));
  }
  out = Eigen::Vector3d((*it)[0].get<double>(), (*it)[1].get<double>(), (*it)[2].get<double>());
  return absl::OkStatus();
}

absl::Status ReadNumber(const nlohmann::json& j, const char* key, double& out) {
  auto it = j.find(key);
  if (it == j.end()) return absl::OkStatus();
  if (!it->is_number()) return absl::InvalidArgumentError(absl::StrCat("reach.", key, " must be a number"));
  out = it->get<double>();
  return absl::OkStatus();
}

}  // namespace

nlohmann::json ReachabilityToJson(const Reachability& r) {
  return {{"approach_direction", VectorOrNull(r.approach_direction)},
          {"max_angle_deg", r.max_angle_deg},
          {"support_point", VectorOrNull(r.support_point)},
          {"support_normal", VectorOrNull(r.support_normal)},
          {"support_clearance_mm", r.support_clearance_mm}};
}

absl::StatusOr<Reachability> ReachabilityFromJson(const nlohmann::json& j) {
  if (!j.is_object()) return absl::InvalidArgumentError("reach must be a JSON object");
  Reachability r;
  for (absl::Status s : {ReadVector(j, "approach_direction", r.approach_direction),
                         ReadVector(j, "support_point", r.support_point),
                         ReadVector(j, "support_normal", r.support_normal),
                         ReadNumber(j, "max_angle_deg", r.max_angle_deg),
                         ReadNumber(j, "support_clearance_mm", r.support_clearance_mm)}) {
    if (!s.ok()) return s;
  }
  std::string why;
  if (!r.IsValid(&why)) return absl::InvalidArgumentError("reach: " + why);
  return r;
}

}  // namespace surfmap
