#include "server/haptics/texture_model_json.h"

#include <cmath>

#include "absl/strings/str_cat.h"
#include "server/haptics/spatial_texture.h"
#include "server/estimate/ar_roots.h"

namespace surfmap::haptics {
namespace {

constexpr std::string_view kModelText =
    "F_t = mu F_n + r(s) against the sliding direction; r(k) = a1 r(k-1) + ... + ap r(k-p) + sigma e(k), "
    "e ~ N(0,1), k = round(s / grid_step_mm), s = arc length slid (mm)";

nlohmann::json Number(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); }

}  // namespace

absl::StatusOr<nlohmann::json> TextureModelToJson(const TextureMap& map) {
  if (absl::Status s = ValidateTextureMap(map); !s.ok()) return s;
  std::vector<int> vertex_count(map.regions.size(), 0);
  int unassigned = 0;
  for (int r : map.region) {
    if (r >= 0) ++vertex_count[r];
    else ++unassigned;
  }
  if (map.region.empty()) unassigned = map.vertex_count();
  nlohmann::json regions = nlohmann::json::array();
  for (size_t i = 0; i < map.regions.size(); ++i) {
    const TextureRegion& r = map.regions[i];
    nlohmann::json j;
    j["region"] = r.region;
    j["mu"] = Number(r.mu);
    j["mu_se"] = Number(r.mu_se);
    j["mu_spread"] = Number(r.mu_spread);
    j["piece_count"] = r.piece_count;
    j["roughness_piece_count"] = r.roughness_piece_count;
    j["ar_order"] = r.ar_coefficients.size();
    j["ar_coefficients"] = r.ar_coefficients;
    j["reflection"] = r.reflection;
    j["sigma"] = Number(r.sigma);
    // Derived, for a renderer that wants the amplitude and the period
    // without an AR library: the process std sigma * sqrt(sum h_j^2) and the
    // spectral peak's wavelength (null for no oscillation).
    double roughness_std = 0.0;
    nlohmann::json wavelength = nullptr;
    if (!r.ar_coefficients.empty() && static_cast<int>(r.ar_coefficients.size()) <= kMaxArOrder && r.sigma > 0) {
      ArImpulse impulse;
      UpdateImpulse(r.ar_coefficients.data(), static_cast<int>(r.ar_coefficients.size()), impulse);
      roughness_std = r.sigma * std::sqrt(impulse.variance_gain);
      if (std::optional<double> steps = ArDominantWavelengthSteps(r.ar_coefficients)) {
        wavelength = *steps * map.grid_step_mm;
      }
    }
    j["roughness_std_n"] = Number(roughness_std);
    j["dominant_wavelength_mm"] = wavelength;
    j["area_mm2"] = Number(r.area_mm2);
    j["vertex_count"] = vertex_count[i];
    regions.push_back(std::move(j));
  }
  nlohmann::json doc;
  doc["format"] = kTextureModelFormat;
  doc["job_id"] = map.job_id;
  doc["level"] = map.level;
  doc["units"] = {{"length", "mm"}, {"force", "N"}, {"mu", "1"}, {"sigma", "N"}, {"grid_step", "mm"}};
  doc["grid_step_mm"] = map.grid_step_mm;
  doc["model"] = kModelText;
  doc["vertex_count"] = map.vertex_count();
  doc["unassigned_vertex_count"] = unassigned;
  doc["regions"] = std::move(regions);
  return doc;
}

absl::StatusOr<TextureModel> TextureModelFromJson(const nlohmann::json& json, std::string_view source) {
  auto fail = [&](const std::string& path, const std::string& what) {
    return absl::InvalidArgumentError(absl::StrCat(std::string(source), ": ", path, ": ", what));
  };
  if (!json.is_object()) return fail("$", "not a JSON object");
  if (!json.contains("format") || json["format"] != kTextureModelFormat) {
    return fail("format", absl::StrCat("not a texture model (expected \"", std::string(kTextureModelFormat), "\")"));
  }
  // NaN is written as null (JSON has no NaN).
  auto number = [&](const nlohmann::json& j, const std::string& path, double* out) -> absl::Status {
    if (j.is_null()) *out = std::nan("");
    else if (j.is_number()) *out = j.get<double>();
    else return fail(path, "not a number");
    return absl::OkStatus();
  };
  auto integer = [&](const nlohmann::json& obj, const char* key, const std::string& path, auto* out) -> absl::Status {
    if (!obj.contains(key) || !obj[key].is_number_integer()) return fail(path + key, "missing or not an integer");
    *out = obj[key].get<std::remove_pointer_t<decltype(out)>>();
    return absl::OkStatus();
  };
  TextureModel model;
  if (absl::Status s = integer(json, "job_id", "", &model.job_id); !s.ok()) return s;
  if (absl::Status s = integer(json, "level", "", &model.level); !s.ok()) return s;
  if (absl::Status s = integer(json, "vertex_count", "", &model.vertex_count); !s.ok()) return s;
  if (!json.contains("grid_step_mm") || !json["grid_step_mm"].is_number() || !(json["grid_step_mm"].get<double>() > 0)) {
    return fail("grid_step_mm", "missing or not a number > 0");
  }
  model.grid_step_mm = json["grid_step_mm"].get<double>();
  if (!json.contains("regions") || !json["regions"].is_array()) return fail("regions", "missing or not an array");
  for (size_t i = 0; i < json["regions"].size(); ++i) {
    const nlohmann::json& j = json["regions"][i];
    const std::string path = absl::StrCat("regions[", i, "].");
    if (!j.is_object()) return fail(path, "not an object");
    TextureRegion r;
    if (absl::Status s = integer(j, "region", path, &r.region); !s.ok()) return s;
    if (absl::Status s = integer(j, "piece_count", path, &r.piece_count); !s.ok()) return s;
    if (absl::Status s = integer(j, "roughness_piece_count", path, &r.roughness_piece_count); !s.ok()) return s;
    for (auto [key, out] : {std::pair{"mu", &r.mu}, std::pair{"mu_se", &r.mu_se}, std::pair{"mu_spread", &r.mu_spread},
                            std::pair{"sigma", &r.sigma}, std::pair{"area_mm2", &r.area_mm2}}) {
      if (!j.contains(key)) return fail(path + key, "missing");
      if (absl::Status s = number(j[key], path + key, out); !s.ok()) return s;
    }
    for (auto [key, out] : {std::pair{"ar_coefficients", &r.ar_coefficients}, std::pair{"reflection", &r.reflection}}) {
      if (!j.contains(key) || !j[key].is_array()) return fail(path + key, "missing or not an array");
      for (size_t m = 0; m < j[key].size(); ++m) {
        double v = 0;
        if (absl::Status s = number(j[key][m], absl::StrCat(path, key, "[", m, "]"), &v); !s.ok()) return s;
        out->push_back(v);
      }
    }
    if (r.ar_coefficients.size() != r.reflection.size()) {
      return fail(path + "reflection", "not as many values as ar_coefficients");
    }
    model.regions.push_back(std::move(r));
  }
  return model;
}

}  // namespace surfmap::haptics
