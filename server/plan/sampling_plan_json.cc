// SamplingPlan::SaveJson / Restore: the complete plan state as JSON.
//
//   {"format": "surfmap.sampling_plan", "version": 2,
//    "options": {...}, "surface": {"vertex_counts": [...], "edge_counts": [...],
//    "triangle_counts": [...]}, "next_sequence": n, "cancelled": false,
//    "measured_order": [vertex, ...], "no_go": [[x, y, z], ...],
//    "sites": [{"vertex", "level", "state", "origin", "failures", "sequence",
//               "reason", "selection_rank", "fit": {"mu", "mu_std", "reflection", "sigma"},
//               "line": {line_sample_json.h}, "parent_a", "parent_b",
//               "parent_distance"}, ...]}
//
// Version 1 (before line samples, reachability and the boundary mode) is
// read too: its measured sites become point samples at their vertices, in
// vertex order.
//
// Doubles are written with round-trip precision, so a restored plan compares
// and scores exactly as the saved one did.
#include <string>

#include <nlohmann/json.hpp>
#include "absl/strings/str_cat.h"
#include "server/plan/line_sample_json.h"
#include "server/plan/sampling_plan.h"
#include "server/plan/reachability_json.h"

namespace surfmap {
namespace {

using nlohmann::json;

constexpr char kFormat[] = "surfmap.sampling_plan";
constexpr int kVersion = 2;

std::string_view WeightsName(LaplacianWeights w) {
  switch (w) {
    case LaplacianWeights::kCotangent:
      return "cotangent";
    case LaplacianWeights::kCotangentClamped:
      return "cotangent_clamped";
    case LaplacianWeights::kUniform:
      return "uniform";
  }
  return "cotangent";
}

// Typed field access with messages that name the field.
class Reader {
 public:
  explicit Reader(absl::Status* status) : status_(status) {}

  const json* Field(const json& j, const std::string& where, const char* key) {
    if (!status_->ok()) return nullptr;
    if (!j.is_object() || !j.contains(key)) {
      Fail(absl::StrCat(where, ".", key, " is missing"));
      return nullptr;
    }
    return &j.at(key);
  }
  double Double(const json& j, const std::string& where, const char* key) {
    const json* f = Field(j, where, key);
    if (f == nullptr) return 0.0;
    if (!f->is_number()) return Fail(absl::StrCat(where, ".", key, " must be a number")), 0.0;
    return f->get<double>();
  }
  std::int64_t Int(const json& j, const std::string& where, const char* key) {
    const json* f = Field(j, where, key);
    if (f == nullptr) return 0;
    if (!f->is_number_integer()) return Fail(absl::StrCat(where, ".", key, " must be an integer")), 0;
    return f->get<std::int64_t>();
  }
  std::uint64_t Unsigned(const json& j, const std::string& where, const char* key) {
    const json* f = Field(j, where, key);
    if (f == nullptr) return 0;
    if (!f->is_number_unsigned()) {
      return Fail(absl::StrCat(where, ".", key, " must be a non-negative integer")), 0;
    }
    return f->get<std::uint64_t>();
  }
  bool Bool(const json& j, const std::string& where, const char* key) {
    const json* f = Field(j, where, key);
    if (f == nullptr) return false;
    if (!f->is_boolean()) return Fail(absl::StrCat(where, ".", key, " must be true or false")), false;
    return f->get<bool>();
  }
  std::string String(const json& j, const std::string& where, const char* key) {
    const json* f = Field(j, where, key);
    if (f == nullptr) return "";
    if (!f->is_string()) return Fail(absl::StrCat(where, ".", key, " must be a string")), "";
    return f->get<std::string>();
  }
  std::vector<double> Doubles(const json& j, const std::string& where, const char* key) {
    const json* f = Field(j, where, key);
    std::vector<double> out;
    if (f == nullptr) return out;
    if (!f->is_array()) return Fail(absl::StrCat(where, ".", key, " must be an array")), out;
    for (const auto& x : *f) {
      if (!x.is_number()) return Fail(absl::StrCat(where, ".", key, " must hold numbers")), out;
      out.push_back(x.get<double>());
    }
    return out;
  }
  void Fail(std::string message) {
    if (status_->ok()) *status_ = absl::InvalidArgumentError(absl::StrCat("plan JSON: ", message));
  }

 private:
  absl::Status* status_;
};

json Vector(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }

json ReachToJson(const Reachability& r) { return ReachabilityToJson(r); }

std::optional<Eigen::Vector3d> OptionalVector(const json& j, const std::string& where, const char* key, Reader& in) {
  auto it = j.find(key);
  if (it == j.end() || it->is_null()) return std::nullopt;
  const std::vector<double> v = in.Doubles(j, where, key);
  if (v.size() != 3) {
    in.Fail(absl::StrCat(where, ".", key, " must hold 3 numbers"));
    return std::nullopt;
  }
  return Eigen::Vector3d(v[0], v[1], v[2]);
}

json OptionsToJson(const SamplingPlanOptions& o) {
  return {
      {"mode", PlanModeName(o.mode)},
      {"coarsest_level", o.coarsest_level},
      {"max_level", o.max_level},
      {"threshold", o.threshold},
      {"distance",
       {{"property", TexturePropertyName(o.distance.property)},
        {"mu_scale", o.distance.mu_scale},
        {"reflection_scale", o.distance.reflection_scale},
        {"log_sigma_scale", o.distance.log_sigma_scale}}},
      {"sample_budget", o.sample_budget},
      {"max_retries", o.max_retries},
      {"probe",
       {{"segment_length_mm", o.probe.segment_length_mm},
        {"speed_mm_s", o.probe.speed_mm_per_s},
        {"normal_force_n", o.probe.normal_force_n}}},
      {"seed", o.seed},
      {"gradient_weight", o.gradient_weight},
      {"min_uncertainty_score", o.min_uncertainty_score},
      {"map",
       {{"weights", WeightsName(o.map.weights)},
        {"correlation_length_mm", o.map.correlation_length_mm},
        {"prior_mu_std_floor", o.map.prior_mu_std_floor}}},
      {"reach", ReachToJson(o.reach)},
      {"regions",
       {{"false_split_probability", o.regions.merge.false_split_probability},
        {"mu_resolution", o.regions.merge.mu_resolution},
        {"spread_resolution", o.regions.merge.spread_resolution},
        {"spread_floor", o.regions.merge.spread_floor},
        {"point_spacing_mm", o.regions.point_spacing_mm},
        {"correlation_length_mm", o.regions.correlation_length_mm},
        {"prior_mu_std_floor", o.regions.prior_mu_std_floor},
        {"min_mu_se", o.regions.min_mu_se},
        {"min_spread", o.regions.min_spread},
        {"change_location_mm", o.regions.change_location_mm}}},
      {"lookahead", o.lookahead},
      {"follow_boundaries", o.follow_boundaries},
      {"coverage_skip_share", o.coverage_skip_share},
      {"quiet_coverage_skip_share", o.quiet_coverage_skip_share},
      {"continuation_prior", o.continuation_prior},
      {"boundary_cost_follows_property", o.boundary_cost_follows_property},
      {"misclassification_cost", o.misclassification_cost},
      {"material_mu_risk", o.material_mu_risk},
      {"small_material_weight_max", o.small_material_weight_max},
      {"far_gain_expected", o.far_gain_expected},
      {"issue_selected_by_gain", o.issue_selected_by_gain},
      {"coarse_direction_by_gain", o.coarse_direction_by_gain},
  };
}

SamplingPlanOptions OptionsFromJson(const json& j, Reader& in) {
  SamplingPlanOptions o;
  const std::string mode = in.String(j, "options", "mode");
  if (auto m = ParsePlanMode(mode)) {
    o.mode = *m;
  } else if (!mode.empty()) {
    in.Fail(absl::StrCat("options.mode \"", mode, "\" is not adaptive, uniform, uncertainty or boundary"));
  }
  o.coarsest_level = static_cast<int>(in.Int(j, "options", "coarsest_level"));
  o.max_level = static_cast<int>(in.Int(j, "options", "max_level"));
  o.threshold = in.Double(j, "options", "threshold");
  if (const json* d = in.Field(j, "options", "distance")) {
    const std::string property = in.String(*d, "options.distance", "property");
    if (std::optional<TextureProperty> p = ParseTextureProperty(property)) {
      o.distance.property = *p;
    } else {
      in.Fail(absl::StrCat("options.distance.property \"", property, "\" is not friction, roughness or both"));
    }
    o.distance.mu_scale = in.Double(*d, "options.distance", "mu_scale");
    o.distance.reflection_scale = in.Double(*d, "options.distance", "reflection_scale");
    o.distance.log_sigma_scale = in.Double(*d, "options.distance", "log_sigma_scale");
  }
  o.sample_budget = static_cast<int>(in.Int(j, "options", "sample_budget"));
  o.max_retries = static_cast<int>(in.Int(j, "options", "max_retries"));
  if (const json* p = in.Field(j, "options", "probe")) {
    o.probe.segment_length_mm = in.Double(*p, "options.probe", "segment_length_mm");
    // "speed_mm_s" as in the job parameters and probe commands; plans saved
    // before the names were one (databases written until 2026-11) say
    // "speed_mm_per_s", and still load.
    const bool old_key = !p->contains("speed_mm_s") && p->contains("speed_mm_per_s");
    o.probe.speed_mm_per_s = in.Double(*p, "options.probe", old_key ? "speed_mm_per_s" : "speed_mm_s");
    o.probe.normal_force_n = in.Double(*p, "options.probe", "normal_force_n");
  }
  o.seed = in.Unsigned(j, "options", "seed");
  o.gradient_weight = in.Double(j, "options", "gradient_weight");
  o.min_uncertainty_score = in.Double(j, "options", "min_uncertainty_score");
  if (const json* m = in.Field(j, "options", "map")) {
    const std::string weights = in.String(*m, "options.map", "weights");
    bool known = false;
    for (auto w : {LaplacianWeights::kCotangent, LaplacianWeights::kCotangentClamped, LaplacianWeights::kUniform}) {
      if (WeightsName(w) == weights) o.map.weights = w, known = true;
    }
    if (!known) in.Fail(absl::StrCat("options.map.weights \"", weights, "\" is not a known weighting"));
    o.map.correlation_length_mm = in.Double(*m, "options.map", "correlation_length_mm");
    o.map.prior_mu_std_floor = in.Double(*m, "options.map", "prior_mu_std_floor");
  }
  // Added in version 2; a version 1 plan has the defaults.
  if (j.contains("reach")) {
    const json& r = j.at("reach");
    o.reach.max_angle_deg = in.Double(r, "options.reach", "max_angle_deg");
    o.reach.support_clearance_mm = in.Double(r, "options.reach", "support_clearance_mm");
    o.reach.approach_direction = OptionalVector(r, "options.reach", "approach_direction", in);
    o.reach.support_point = OptionalVector(r, "options.reach", "support_point", in);
    o.reach.support_normal = OptionalVector(r, "options.reach", "support_normal", in);
  }
  if (j.contains("regions")) {
    const json& r = j.at("regions");
    const std::string w = "options.regions";
    o.regions.merge.false_split_probability = in.Double(r, w, "false_split_probability");
    o.regions.merge.mu_resolution = in.Double(r, w, "mu_resolution");
    o.regions.merge.spread_resolution = in.Double(r, w, "spread_resolution");
    o.regions.point_spacing_mm = in.Double(r, w, "point_spacing_mm");
    o.regions.correlation_length_mm = in.Double(r, w, "correlation_length_mm");
    o.regions.prior_mu_std_floor = in.Double(r, w, "prior_mu_std_floor");
    o.regions.min_mu_se = in.Double(r, w, "min_mu_se");
    o.regions.min_spread = in.Double(r, w, "min_spread");
    // Added after "regions" itself: plans saved by builds in between keep the default.
    if (r.contains("change_location_mm")) o.regions.change_location_mm = in.Double(r, w, "change_location_mm");
    // Added later still: a plan saved before compares spreads however small, as it did.
    o.regions.merge.spread_floor = r.contains("spread_floor") ? in.Double(r, w, "spread_floor") : 0.0;
  }
  if (j.contains("lookahead")) o.lookahead = static_cast<int>(in.Int(j, "options", "lookahead"));
  // Added later: a plan saved before goes on choosing as it did.
  o.follow_boundaries = j.contains("follow_boundaries") && in.Bool(j, "options", "follow_boundaries");
  // Added later: a plan saved before goes on dragging every coarsest-level site.
  o.coverage_skip_share = j.contains("coverage_skip_share") ? in.Double(j, "options", "coverage_skip_share") : 0.0;
  o.quiet_coverage_skip_share =
      j.contains("quiet_coverage_skip_share") ? in.Double(j, "options", "quiet_coverage_skip_share") : 0.0;
  o.continuation_prior = j.contains("continuation_prior") ? in.Double(j, "options", "continuation_prior") : 0.0;
  // Added later: a plan saved before goes on weighing boundaries by their mu jump, whatever its property.
  o.boundary_cost_follows_property = j.contains("boundary_cost_follows_property") && in.Bool(j, "options", "boundary_cost_follows_property");
  // Added later: a plan saved before goes on weighing squared error alone.
  o.misclassification_cost =
      j.contains("misclassification_cost") ? in.Double(j, "options", "misclassification_cost") : 0.0;
  // Added later: a plan saved before goes on without the materials' mu risk.
  o.material_mu_risk = j.contains("material_mu_risk") && in.Bool(j, "options", "material_mu_risk");
  // Added later: a plan saved before goes on weighing every boundary alike.
  o.small_material_weight_max =
      j.contains("small_material_weight_max") ? in.Double(j, "options", "small_material_weight_max") : 1.0;
  // Added later: a plan saved before goes on counting a corridor's far
  // variance in full.
  o.far_gain_expected = j.contains("far_gain_expected") && in.Bool(j, "options", "far_gain_expected");
  // Added later: a plan saved before goes on issuing its choices in the
  // plan's issue order.
  o.issue_selected_by_gain = j.contains("issue_selected_by_gain") && in.Bool(j, "options", "issue_selected_by_gain");
  o.coarse_direction_by_gain =
      j.contains("coarse_direction_by_gain") && in.Bool(j, "options", "coarse_direction_by_gain");
  return o;
}

json SurfaceToJson(const std::vector<const SurfaceLevel*>& levels) {
  json vertices = json::array(), edges = json::array(), triangles = json::array();
  for (const SurfaceLevel* l : levels) {
    vertices.push_back(l->limit_positions.size());
    edges.push_back(l->edges.size());
    triangles.push_back(l->triangles.size());
  }
  return {{"vertex_counts", vertices}, {"edge_counts", edges}, {"triangle_counts", triangles}};
}

}  // namespace

std::string SamplingPlan::SaveJson() const {
  json sites = json::array();
  for (const auto& [v, r] : sites_) {
    json s = {{"vertex", v},
              {"level", r.site.level},
              {"state", SiteStateName(r.state)},
              {"origin", SiteOriginName(r.origin)},
              {"failures", r.failures},
              {"sequence", r.sequence},
              {"reason", r.reason}};
    if (r.selection_rank > 0) s["selection_rank"] = r.selection_rank;
    if (r.fit) {
      s["fit"] = {{"mu", r.fit->mu},
                  {"mu_std", r.fit->mu_std},
                  {"reflection", r.fit->reflection},
                  {"sigma", r.fit->sigma}};
    }
    if (r.line) s["line"] = LineSampleToJson(*r.line);
    if (r.origin == SiteOrigin::kRefined) {
      s["parent_a"] = r.parent_a;
      s["parent_b"] = r.parent_b;
      s["parent_distance"] = r.parent_distance;
    }
    sites.push_back(std::move(s));
  }
  json no_go = json::array();
  for (const Eigen::Vector3d& p : no_go_) no_go.push_back(Vector(p));
  json imported = json::array();
  for (const ImportedDrag& d : imported_) {
    imported.push_back({{"line", LineSampleToJson(d.line)}, {"position", Vector(d.position)}});
  }
  json j = {{"format", kFormat},
            {"version", kVersion},
            {"options", OptionsToJson(options_)},
            {"surface", SurfaceToJson(levels_)},
            {"next_sequence", next_sequence_},
            {"cancelled", cancelled_},
            {"measured_order", measured_order_},
            {"imported", std::move(imported)},
            {"no_go", std::move(no_go)},
            {"sites", std::move(sites)}};
  return j.dump();
}

absl::StatusOr<SamplingPlan> SamplingPlan::Restore(std::string_view text, std::vector<const SurfaceLevel*> levels) {
  json j = json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (j.is_discarded()) return absl::InvalidArgumentError("plan JSON: not valid JSON");
  absl::Status status;
  Reader in(&status);
  const std::string format = in.String(j, "plan", "format");
  if (status.ok() && format != kFormat) {
    return absl::InvalidArgumentError(absl::StrCat("plan JSON: format \"", format, "\" is not ", kFormat));
  }
  const std::int64_t version = in.Int(j, "plan", "version");
  if (status.ok() && version != kVersion && version != 1) {
    return absl::InvalidArgumentError(
        absl::StrCat("plan JSON: version ", version, " is not supported (this build reads version ", kVersion, ")"));
  }
  SamplingPlan plan;
  if (const json* o = in.Field(j, "plan", "options")) plan.options_ = OptionsFromJson(*o, in);
  if (!status.ok()) return status;
  plan.levels_ = std::move(levels);
  if (auto s = plan.Initialise(); !s.ok()) return s;

  // The surface must be the one the plan was made for.
  if (const json* s = in.Field(j, "plan", "surface")) {
    const json expected = SurfaceToJson(plan.levels_);
    for (const char* key : {"vertex_counts", "edge_counts", "triangle_counts"}) {
      const json* saved = in.Field(*s, "surface", key);
      if (saved != nullptr && *saved != expected.at(key)) {
        in.Fail(absl::StrCat("surface.", key, " ", saved->dump(), " differ from the given surface's ",
                             expected.at(key).dump()));
      }
    }
  }
  plan.next_sequence_ = in.Unsigned(j, "plan", "next_sequence");
  plan.cancelled_ = in.Bool(j, "plan", "cancelled");
  const json* sites = in.Field(j, "plan", "sites");
  if (!status.ok()) return status;
  if (!sites->is_array()) return absl::InvalidArgumentError("plan JSON: sites must be an array");
  if (plan.next_sequence_ == 0) return absl::InvalidArgumentError("plan JSON: next_sequence must be >= 1");

  const int candidates = plan.VertexCount(plan.options_.max_level);
  for (size_t i = 0; i < sites->size(); ++i) {
    const json& js = (*sites)[i];
    const std::string where = absl::StrCat("sites[", i, "]");
    SiteRecord r;
    const std::int64_t vertex = in.Int(js, where, "vertex");
    r.site.level = static_cast<int>(in.Int(js, where, "level"));
    const std::string state = in.String(js, where, "state");
    const std::string origin = in.String(js, where, "origin");
    const std::int64_t failures = in.Int(js, where, "failures");
    r.sequence = in.Unsigned(js, where, "sequence");
    r.reason = in.String(js, where, "reason");
    if (!status.ok()) return status;
    if (vertex < 0 || vertex >= candidates) {
      return absl::InvalidArgumentError(absl::StrCat("plan JSON: ", where, ".vertex ", vertex,
                                                     " is outside level ", plan.options_.max_level, "'s 0..",
                                                     candidates - 1));
    }
    r.site.vertex = static_cast<int>(vertex);
    const int expected_level = std::max(plan.options_.coarsest_level, plan.NaturalLevel(r.site.vertex));
    if (r.site.level != expected_level) {
      return absl::InvalidArgumentError(absl::StrCat("plan JSON: ", where, ".level ", r.site.level, " for vertex ",
                                                     vertex, " should be ", expected_level));
    }
    bool known_state = false;
    for (auto s : {SiteState::kPending, SiteState::kIssued, SiteState::kMeasured, SiteState::kFailed,
                   SiteState::kSkipped}) {
      if (SiteStateName(s) == state) r.state = s, known_state = true;
    }
    if (!known_state) return absl::InvalidArgumentError(absl::StrCat("plan JSON: ", where, ".state \"", state, "\" is unknown"));
    bool known_origin = false;
    for (auto o : {SiteOrigin::kInitial, SiteOrigin::kRefined, SiteOrigin::kSelected}) {
      if (SiteOriginName(o) == origin) r.origin = o, known_origin = true;
    }
    if (!known_origin) {
      return absl::InvalidArgumentError(absl::StrCat("plan JSON: ", where, ".origin \"", origin, "\" is unknown"));
    }
    if (failures < 0 || failures > plan.options_.max_retries + 1) {
      return absl::InvalidArgumentError(absl::StrCat("plan JSON: ", where, ".failures ", failures,
                                                     " is outside 0..", plan.options_.max_retries + 1));
    }
    r.failures = static_cast<int>(failures);
    if (js.contains("selection_rank")) {  // added later: sites saved before have none
      const std::int64_t rank = in.Int(js, where, "selection_rank");
      if (!status.ok()) return status;
      if (r.origin != SiteOrigin::kSelected || rank < 1 || rank > plan.options_.lookahead) {
        return absl::InvalidArgumentError(absl::StrCat("plan JSON: ", where, ".selection_rank ", rank,
                                                       " is not a selected site's 1..", plan.options_.lookahead));
      }
      r.selection_rank = static_cast<int>(rank);
    }
    if (r.sequence >= plan.next_sequence_) {
      return absl::InvalidArgumentError(absl::StrCat("plan JSON: ", where, ".sequence ", r.sequence,
                                                     " is not below next_sequence ", plan.next_sequence_));
    }
    if (r.origin == SiteOrigin::kRefined) {
      r.parent_a = static_cast<int>(in.Int(js, where, "parent_a"));
      r.parent_b = static_cast<int>(in.Int(js, where, "parent_b"));
      r.parent_distance = in.Double(js, where, "parent_distance");
    }
    if (r.state == SiteState::kMeasured) {
      const json* f = in.Field(js, where, "fit");
      if (f != nullptr) {
        const std::string fw = where + ".fit";
        TextureParams fit;
        fit.mu = in.Double(*f, fw, "mu");
        fit.mu_std = in.Double(*f, fw, "mu_std");
        fit.reflection = in.Doubles(*f, fw, "reflection");
        fit.sigma = in.Double(*f, fw, "sigma");
        r.fit = fit;
      }
      if (js.contains("line")) {
        absl::StatusOr<LineSample> line = LineSampleFromJson(js.at("line"), "plan JSON: " + where + ".line");
        if (!line.ok()) return line.status();
        r.line = *std::move(line);
      } else if (r.fit) {
        r.line = PointLineSample(plan.levels_.back()->limit_positions[r.site.vertex], *r.fit);  // version 1
      }
    }
    if (!status.ok()) return status;
    if (r.fit) {
      if (auto s = ValidateFit(*r.fit); !s.ok()) {
        return absl::InvalidArgumentError(absl::StrCat("plan JSON: ", where, ".", s.message()));
      }
    }
    if (plan.sites_.count(r.site.vertex)) {
      return absl::InvalidArgumentError(absl::StrCat("plan JSON: ", where, " repeats vertex ", vertex));
    }
    switch (r.state) {
      case SiteState::kPending:
        plan.pending_.insert(plan.KeyOf(r));
        break;
      case SiteState::kIssued:
        if (r.sequence == 0 || plan.outstanding_.count(r.sequence)) {
          return absl::InvalidArgumentError(
              absl::StrCat("plan JSON: ", where, " is issued with a missing or repeated sequence ", r.sequence));
        }
        plan.outstanding_[r.sequence] = r.site.vertex;
        break;
      case SiteState::kMeasured:
        ++plan.measured_count_;
        break;
      default:
        break;
    }
    plan.CountSite(r, +1);
    plan.sites_.emplace(r.site.vertex, std::move(r));
  }
  // The order in which drags were measured (the map's piece order).
  if (j.contains("measured_order")) {
    const std::vector<double> order = in.Doubles(j, "plan", "measured_order");
    if (!status.ok()) return status;
    for (double x : order) {
      const int v = static_cast<int>(x);
      const SiteRecord* r = plan.FindSite(v);
      if (r == nullptr || r->state != SiteState::kMeasured || x != v) {
        return absl::InvalidArgumentError(absl::StrCat("plan JSON: measured_order names ", x, ", not a measured site"));
      }
      plan.measured_order_.push_back(v);
    }
    if (static_cast<int>(plan.measured_order_.size()) != plan.measured_count_) {
      return absl::InvalidArgumentError(absl::StrCat("plan JSON: measured_order has ", plan.measured_order_.size(),
                                                     " sites, ", plan.measured_count_, " are measured"));
    }
  } else {
    for (const auto& [v, r] : plan.sites_) {
      if (r.state == SiteState::kMeasured) plan.measured_order_.push_back(v);
    }
  }
  // Imported drags (absent in plans saved before imports existed).
  if (j.contains("imported")) {
    const json& imported = j.at("imported");
    if (!imported.is_array()) return absl::InvalidArgumentError("plan JSON: imported must be an array");
    for (std::size_t i = 0; i < imported.size(); ++i) {
      const std::string where = absl::StrCat("plan JSON: imported[", i, "]");
      const json& d = imported[i];
      if (!d.is_object() || !d.contains("line") || !d.contains("position")) {
        return absl::InvalidArgumentError(absl::StrCat(where, " must hold a line and a position"));
      }
      absl::StatusOr<LineSample> line = LineSampleFromJson(d.at("line"), where + ".line");
      if (!line.ok()) return line.status();
      const json& p = d.at("position");
      if (!p.is_array() || p.size() != 3 || !p[0].is_number() || !p[1].is_number() || !p[2].is_number()) {
        return absl::InvalidArgumentError(absl::StrCat(where, ".position must be 3 numbers"));
      }
      plan.imported_.push_back({std::move(*line), Eigen::Vector3d(p[0].get<double>(), p[1].get<double>(),
                                                                   p[2].get<double>())});
    }
  }
  if (j.contains("no_go")) {
    const json& no_go = j.at("no_go");
    if (!no_go.is_array()) return absl::InvalidArgumentError("plan JSON: no_go must be an array");
    for (std::size_t i = 0; i < no_go.size(); ++i) {
      const json& p = no_go[i];
      if (!p.is_array() || p.size() != 3 || !p[0].is_number() || !p[1].is_number() || !p[2].is_number()) {
        return absl::InvalidArgumentError(absl::StrCat("plan JSON: no_go[", i, "] must be 3 numbers"));
      }
      plan.no_go_.emplace_back(p[0].get<double>(), p[1].get<double>(), p[2].get<double>());
    }
  }
  if (auto s = plan.RefreshSelection(); !s.ok()) return s;
  if (auto s = plan.RefreshBoundarySelection(); !s.ok()) return s;
  return plan;
}

}  // namespace surfmap
