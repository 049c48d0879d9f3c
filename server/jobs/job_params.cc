#include "server/jobs/job_params.h"

#include <algorithm>
#include <cmath>

#include "absl/strings/str_cat.h"
#include "server/codec/fit_json.h"
#include "server/map/map_level.h"
#include "server/plan/reachability_json.h"

namespace surfmap {
namespace {

// Field name, accessor: one list for both directions of the JSON form.
template <typename Limits, typename Visit>
void ForEachLimit(Limits& l, Visit visit) {
  visit("max_offset_mm", l.max_offset_mm);
  visit("min_length_fraction", l.min_length_fraction);
  visit("max_length_fraction", l.max_length_fraction);
  visit("max_direction_deg", l.max_direction_deg);
  visit("max_normal_deg", l.max_normal_deg);
  visit("normal_force_factor", l.normal_force_factor);
  visit("max_mu", l.max_mu);
  visit("max_duration_factor", l.max_duration_factor);
  visit("min_rate_hz", l.min_rate_hz);
  visit("max_rate_hz", l.max_rate_hz);
}

}  // namespace

nlohmann::json TraceLimitsToJson(const TraceLimits& limits) {
  nlohmann::json j = nlohmann::json::object();
  ForEachLimit(limits, [&](const char* name, double value) { j[name] = value; });
  return j;
}

absl::StatusOr<TraceLimits> TraceLimitsFromJson(const nlohmann::json& j) {
  if (!j.is_object()) return absl::InvalidArgumentError("job params: limits must be a JSON object");
  TraceLimits limits;
  absl::Status status;
  ForEachLimit(limits, [&](const char* name, double& value) {
    if (status.ok() && j.contains(name)) {
      if (!j.at(name).is_number()) {
        status = absl::InvalidArgumentError(absl::StrCat("job params: limits.", name, " must be a number"));
      } else {
        value = j.at(name).get<double>();
      }
    }
  });
  if (!status.ok()) return status;
  return limits;
}

bool JobParams::IsValid(std::string* why) const {
  auto fail = [&](std::string text) {
    *why = std::move(text);
    return false;
  };
  if (object_id <= 0) return fail("object_id must be positive");
  if (coarsest_level < 0 || coarsest_level > 6) return fail("coarsest_level must be in 0..6");
  if (finest_level < coarsest_level || finest_level > 6) return fail("finest_level must be in coarsest_level..6");
  if (map_level < finest_level || map_level > 6) return fail("map_level must be in finest_level..6");
  if (std::string reach_why; !reach.IsValid(&reach_why)) return fail("reach: " + reach_why);
  if (!std::isfinite(threshold) || threshold <= 0) return fail("threshold must be a positive number");
  if (budget < 0) return fail("budget must be >= 0 (0 = unlimited)");
  if (!(probe.segment_length_mm >= 1 && probe.segment_length_mm <= 200)) return fail("segment length must be in [1, 200] mm");
  if (!(probe.speed_mm_per_s > 0 && probe.speed_mm_per_s <= 500)) return fail("speed must be in (0, 500] mm/s");
  if (!(probe.normal_force_n > 0 && probe.normal_force_n <= 100)) return fail("normal force must be in (0, 100] N");
  if (!(site_spacing_mm >= 0 && site_spacing_mm <= 1000)) return fail("site spacing must be in [0, 1000] mm");
  if (max_retries < 0 || max_retries > 100) return fail("max_retries must be in 0..100");
  if (lease_ms < 100 || lease_ms > 86'400'000) return fail("lease must be between 0.1 s and 24 h");
  std::string fit_why;
  if (!fit.IsValid(&fit_why)) return fail("estimator settings: " + fit_why);
  std::string limits_why;
  if (!limits.IsValid(&limits_why)) return fail("trace limits: " + limits_why);
  return true;
}

PlanRequest PlanRequestOf(const JobParams& p) {
  return {.mode = p.mode,
          .coarsest_level = p.coarsest_level,
          .finest_level = p.finest_level,
          .threshold = p.threshold,
          .property = p.property,
          .budget = p.budget,
          .max_retries = p.max_retries,
          .probe = p.probe,
          .seed = p.seed,
          .reach = p.reach};
}

SamplingPlanOptions PlanOptionsFor(const JobParams& p) { return PlanOptionsFor(PlanRequestOf(p)); }

void ResolveAutoLevels(const SurfaceLevel& control, JobParams& p) {
  const int auto_map = MapLevelFor(control);
  if (p.finest_level == kAutoLevel) {
    const int map = p.map_level == kAutoLevel ? auto_map : p.map_level;
    p.finest_level = std::max(p.coarsest_level, map - kPlanLevelsBelowMap);
  }
  if (p.map_level == kAutoLevel) p.map_level = std::max(p.finest_level, auto_map);
}

std::vector<const SurfaceLevel*> JobPlanLevels(const LoopSurface& surface, const JobParams& p) {
  std::vector<const SurfaceLevel*> levels;
  for (int k = 0; k <= std::min(p.finest_level, surface.max_level()); ++k) levels.push_back(&surface.level(k));
  return levels;
}

nlohmann::json JobParamsToJson(const JobParams& p) {
  return {{"object_id", p.object_id},
          {"property", TexturePropertyName(p.property)},
          {"mode", std::string(PlanModeName(p.mode))},
          {"coarsest_level", p.coarsest_level},
          {"finest_level", p.finest_level},
          {"map_level", p.map_level},
          {"reach", ReachabilityToJson(p.reach)},
          {"threshold", p.threshold},
          {"budget", p.budget},
          {"probe",
           {{"segment_length_mm", p.probe.segment_length_mm},
            {"speed_mm_s", p.probe.speed_mm_per_s},
            {"normal_force_n", p.probe.normal_force_n}}},
          {"seed", p.seed},
          {"max_retries", p.max_retries},
          {"lease_ms", p.lease_ms},
          {"fit", FitOptionsToJson(p.fit)},
          {"limits", TraceLimitsToJson(p.limits)},
          {"site_spacing_mm", p.site_spacing_mm}};
}

absl::StatusOr<JobParams> JobParamsFromJson(const nlohmann::json& j) {
  JobParams p;
  try {
    p.object_id = j.at("object_id").get<int64_t>();
    const std::string property = j.at("property").get<std::string>();
    std::optional<TextureProperty> parsed_property = ParseTextureProperty(property);
    if (parsed_property) p.property = *parsed_property;
    else return absl::InvalidArgumentError(absl::StrCat("job params: unknown property '", property, "'"));
    const std::string mode = j.at("mode").get<std::string>();
    std::optional<PlanMode> parsed_mode = ParsePlanMode(mode);
    if (parsed_mode) p.mode = *parsed_mode;
    else return absl::InvalidArgumentError(absl::StrCat("job params: unknown mode '", mode, "'"));
    p.coarsest_level = j.at("coarsest_level").get<int>();
    p.finest_level = j.at("finest_level").get<int>();
    // Jobs stored before map levels: the map was on the plan's finest level.
    p.map_level = j.contains("map_level") ? j.at("map_level").get<int>() : p.finest_level;
    if (j.contains("reach")) {
      absl::StatusOr<Reachability> reach = ReachabilityFromJson(j.at("reach"));
      if (!reach.ok()) return absl::InvalidArgumentError(absl::StrCat("job params: ", reach.status().message()));
      p.reach = *reach;
    }
    p.threshold = j.at("threshold").get<double>();
    p.budget = j.at("budget").get<int>();
    p.probe.segment_length_mm = j.at("probe").at("segment_length_mm").get<double>();
    p.probe.speed_mm_per_s = j.at("probe").at("speed_mm_s").get<double>();
    p.probe.normal_force_n = j.at("probe").at("normal_force_n").get<double>();
    p.seed = j.at("seed").get<uint64_t>();
    p.max_retries = j.at("max_retries").get<int>();
    p.lease_ms = j.at("lease_ms").get<int64_t>();
    absl::StatusOr<FitOptions> fit = FitOptionsFromJson(j.at("fit"));
    if (!fit.ok()) return fit.status();
    p.fit = *fit;
    p.site_spacing_mm = j.value("site_spacing_mm", 0.0);  // absent in jobs stored before it existed
    if (j.contains("limits")) {  // jobs stored before limits existed take the defaults
      absl::StatusOr<TraceLimits> limits = TraceLimitsFromJson(j.at("limits"));
      if (!limits.ok()) return limits.status();
      p.limits = *limits;
    }
  } catch (const nlohmann::json::exception& e) {
    return absl::InvalidArgumentError(absl::StrCat("job params: ", e.what()));
  }
  std::string why;
  if (!p.IsValid(&why)) return absl::InvalidArgumentError("job params: " + why);
  return p;
}

}  // namespace surfmap
