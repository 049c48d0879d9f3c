#include "server/jobs/command_json.h"

#include <nlohmann/json.hpp>
#include "absl/strings/str_cat.h"

namespace surfmap {
namespace {

nlohmann::json Vec(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }

Eigen::Vector3d VecFrom(const nlohmann::json& j) {
  if (!j.is_array() || j.size() != 3) throw std::runtime_error("expected [x, y, z]");
  return {j[0].get<double>(), j[1].get<double>(), j[2].get<double>()};
}

}  // namespace

std::string ProbeCommandToJson(const ProbeCommand& c) {
  nlohmann::json j{{"sequence", c.sequence},
                   {"level", c.site.level},
                   {"vertex", c.site.vertex},
                   {"attempt", c.attempt},
                   {"position", Vec(c.position)},
                   {"normal", Vec(c.normal)},
                   {"drag_direction", Vec(c.drag_direction)},
                   {"segment_length_mm", c.probe.segment_length_mm},
                   {"speed_mm_s", c.probe.speed_mm_per_s},
                   {"normal_force_n", c.probe.normal_force_n}};
  return j.dump();
}

absl::StatusOr<ProbeCommand> ProbeCommandFromJson(const std::string& text) {
  nlohmann::json j = nlohmann::json::parse(text, nullptr, false);
  if (j.is_discarded() || !j.is_object()) return absl::DataLossError("stored probe command is not a JSON object");
  ProbeCommand c;
  try {
    c.sequence = j.at("sequence").get<uint64_t>();
    c.site.level = j.at("level").get<int>();
    c.site.vertex = j.at("vertex").get<int>();
    c.attempt = j.at("attempt").get<int>();
    c.position = VecFrom(j.at("position"));
    c.normal = VecFrom(j.at("normal"));
    c.drag_direction = VecFrom(j.at("drag_direction"));
    c.probe.segment_length_mm = j.at("segment_length_mm").get<double>();
    c.probe.speed_mm_per_s = j.at("speed_mm_s").get<double>();
    c.probe.normal_force_n = j.at("normal_force_n").get<double>();
  } catch (const std::exception& e) {
    return absl::DataLossError(absl::StrCat("stored probe command: ", e.what()));
  }
  return c;
}

}  // namespace surfmap
