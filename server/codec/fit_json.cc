#include "server/codec/fit_json.h"

#include <set>

#include "absl/strings/str_cat.h"

namespace surfmap {
namespace {

using nlohmann::json;

json OptionalNumber(const std::optional<double>& v) { return v ? json(*v) : json(nullptr); }

const char* ArMethodName(ArMethod m) { return m == ArMethod::kBurg ? "burg" : "ls"; }

// Reads a key of the expected JSON type into `out`; absent keys leave `out`.
template <typename T>
absl::Status ReadKey(const json& j, const char* key, T* out) {
  auto it = j.find(key);
  if (it == j.end() || it->is_null()) return absl::OkStatus();
  try {
    *out = it->get<T>();
  } catch (const json::exception& e) {
    return absl::InvalidArgumentError(absl::StrCat("key '", key, "': ", e.what()));
  }
  return absl::OkStatus();
}

// The roughness keys of a fit (also used per piece).
void PutRoughness(const ArFit& r, json& j) {
  j["a"] = r.a;
  j["a_stderr"] = r.a_stderr;
  j["a1"] = r.a.size() > 0 ? json(r.a[0]) : json(nullptr);
  j["a2"] = r.a.size() > 1 ? json(r.a[1]) : json(nullptr);
  j["sigma"] = r.sigma;
  j["variance"] = r.variance;
  j["stationary"] = r.stationary;
  j["reflection"] = r.reflection;
  j["acf_decay_mm"] = r.acf_decay_mm;
  j["dominant_wavelength_mm"] = OptionalNumber(r.dominant_wavelength_mm);
  j["below_noise_floor"] = r.below_noise_floor;
  j["roughness_n"] = r.n;
}

absl::Status GetRoughness(const json& j, ArFit& r) {
  if (auto it = j.find("dominant_wavelength_mm"); it != j.end() && it->is_number()) {
    r.dominant_wavelength_mm = it->get<double>();
  }
  for (absl::Status s :
       {ReadKey(j, "a", &r.a), ReadKey(j, "a_stderr", &r.a_stderr), ReadKey(j, "sigma", &r.sigma),
        ReadKey(j, "variance", &r.variance), ReadKey(j, "stationary", &r.stationary),
        ReadKey(j, "reflection", &r.reflection), ReadKey(j, "acf_decay_mm", &r.acf_decay_mm),
        ReadKey(j, "below_noise_floor", &r.below_noise_floor), ReadKey(j, "roughness_n", &r.n)}) {
    if (!s.ok()) return s;
  }
  return absl::OkStatus();
}

json PieceToJson(const DragPiece& p) {
  json j{{"start_mm", p.start_mm},
         {"end_mm", p.end_mm},
         {"first_pair", p.first_pair},
         {"pairs", p.pair_count},
         {"starts_at_change", p.starts_at_change},
         {"ends_at_change", p.ends_at_change},
         {"mu", p.mu},
         {"mu_std", p.mu_std},
         {"mu_median", p.mu_median},
         {"mu_se", p.mu_se},
         {"effective_pairs", p.effective_pairs},
         {"roughness", std::string(PieceRoughnessName(p.roughness_state))}};
  if (!p.roughness_note.empty()) j["roughness_note"] = p.roughness_note;
  if (p.roughness_state == PieceRoughness::kFitted) {
    json r;
    PutRoughness(p.roughness, r);
    j["fit"] = r;
  }
  return j;
}

absl::StatusOr<DragPiece> PieceFromJson(const json& j, std::size_t index) {
  auto where = [index](const absl::Status& s) {
    return absl::Status(s.code(), absl::StrCat("pieces[", index, "]: ", s.message()));
  };
  if (!j.is_object()) return absl::InvalidArgumentError(absl::StrCat("pieces[", index, "] must be an object"));
  DragPiece p;
  std::string state;
  for (absl::Status s :
       {ReadKey(j, "start_mm", &p.start_mm), ReadKey(j, "end_mm", &p.end_mm), ReadKey(j, "first_pair", &p.first_pair),
        ReadKey(j, "pairs", &p.pair_count), ReadKey(j, "starts_at_change", &p.starts_at_change),
        ReadKey(j, "ends_at_change", &p.ends_at_change), ReadKey(j, "mu", &p.mu), ReadKey(j, "mu_std", &p.mu_std),
        ReadKey(j, "mu_median", &p.mu_median), ReadKey(j, "mu_se", &p.mu_se),
        ReadKey(j, "effective_pairs", &p.effective_pairs), ReadKey(j, "roughness", &state),
        ReadKey(j, "roughness_note", &p.roughness_note)}) {
    if (!s.ok()) return where(s);
  }
  bool known = false;
  for (PieceRoughness r : {PieceRoughness::kFitted, PieceRoughness::kTooShort, PieceRoughness::kFitFailed}) {
    if (PieceRoughnessName(r) == state) p.roughness_state = r, known = true;
  }
  if (!known) {
    return absl::InvalidArgumentError(absl::StrCat("pieces[", index, "].roughness '", state,
                                                   "' is not fitted, too_short or fit_failed"));
  }
  if (p.roughness_state == PieceRoughness::kFitted) {
    auto it = j.find("fit");
    if (it == j.end() || !it->is_object()) {
      return absl::InvalidArgumentError(absl::StrCat("pieces[", index, "] is fitted but has no 'fit' object"));
    }
    if (absl::Status s = GetRoughness(*it, p.roughness); !s.ok()) return where(s);
  }
  return p;
}

}  // namespace

json FitOptionsToJson(const FitOptions& o) {
  return json{{"step_mm", o.step_mm},
              {"ar_order", o.ar_order},
              {"ar_method", ArMethodName(o.ar_method)},
              {"noise_aware", o.noise_aware},
              {"noise_replicates", o.noise_replicates},
              {"series_normal_halfwidth_mm", o.series.halfwidth_mm},
              {"series_normal_max_turn_deg", o.series.max_turn_deg},
              {"series_follows_samples", o.series.follow_samples},
              {"window_trim_fraction", o.window_trim_fraction},
              {"change_false_alarm", o.changes.false_alarm_probability},
              {"min_piece_mm", o.changes.min_piece_mm},
              {"change_group_spacing_mm", o.changes.group_spacing_mm},
              {"min_roughness_piece_mm", o.min_roughness_piece_mm},
              {"change_guard_mm", o.change_guard_mm},
              {"path_step_mm", o.path_step_mm}};
}

absl::StatusOr<FitOptions> FitOptionsFromJson(const json& j) {
  if (!j.is_object()) return absl::InvalidArgumentError("estimator options must be a JSON object");
  static const std::set<std::string> kKnown = {"step_mm", "ar_order", "ar_method", "noise_aware", "noise_replicates",
                                               "series_normal_halfwidth_mm", "series_normal_max_turn_deg", "series_follows_samples",
                                               "window_trim_fraction", "change_false_alarm", "min_piece_mm",
                                               "change_group_spacing_mm", "min_roughness_piece_mm", "change_guard_mm", "path_step_mm"};
  for (auto it = j.begin(); it != j.end(); ++it) {
    if (!kKnown.count(it.key())) return absl::InvalidArgumentError(absl::StrCat("unknown estimator option '", it.key(), "'"));
  }
  FitOptions o;
  std::string method = ArMethodName(o.ar_method);
  for (absl::Status s : {ReadKey(j, "step_mm", &o.step_mm), ReadKey(j, "ar_order", &o.ar_order),
                         ReadKey(j, "ar_method", &method), ReadKey(j, "noise_aware", &o.noise_aware),
                         ReadKey(j, "noise_replicates", &o.noise_replicates),
                         ReadKey(j, "series_normal_halfwidth_mm", &o.series.halfwidth_mm),
                         ReadKey(j, "series_normal_max_turn_deg", &o.series.max_turn_deg),
                         ReadKey(j, "series_follows_samples", &o.series.follow_samples),
                         ReadKey(j, "window_trim_fraction", &o.window_trim_fraction),
                         ReadKey(j, "change_false_alarm", &o.changes.false_alarm_probability),
                         ReadKey(j, "min_piece_mm", &o.changes.min_piece_mm),
                         ReadKey(j, "change_group_spacing_mm", &o.changes.group_spacing_mm),
                         ReadKey(j, "min_roughness_piece_mm", &o.min_roughness_piece_mm),
                         ReadKey(j, "change_guard_mm", &o.change_guard_mm),
                         ReadKey(j, "path_step_mm", &o.path_step_mm)}) {
    if (!s.ok()) return s;
  }
  if (method == "burg") {
    o.ar_method = ArMethod::kBurg;
  } else if (method == "ls") {
    o.ar_method = ArMethod::kLeastSquares;
  } else {
    return absl::InvalidArgumentError(absl::StrCat("ar_method must be 'burg' or 'ls', got '", method, "'"));
  }
  std::string why;
  if (!o.IsValid(&why)) return absl::InvalidArgumentError(why);
  return o;
}

json TraceFitToJson(const TraceFit& fit, bool with_series) {
  const FrictionFit& f = fit.friction;
  json j{{"mu", f.mu},
         {"mu_std", f.mu_std},
         {"mu_median", f.mu_median},
         {"normal", {f.normal.x(), f.normal.y(), f.normal.z()}},
         {"n_pairs", f.n_pairs},
         {"window_mm", {f.window_start_mm, f.window_end_mm}},
         {"noise_std", fit.noise_std},
         {"path_length_mm", fit.path_length_mm},
         {"roughness_piece", fit.roughness_piece}};
  PutRoughness(fit.roughness, j);
  json changes = json::array();
  for (const ChangePoint& c : fit.changes) {
    changes.push_back({{"s_mm", c.s_mm},
                       {"pair", c.index},
                       {"statistic", c.statistic},
                       {"critical_value", c.critical_value}});
  }
  j["changes"] = changes;
  // Written only where the pairs were grouped (a rig faster than 100 Hz at
  // 10 mm/s), so the fits of the rigs before keep their bytes.
  if (fit.pairs_per_group != 1) j["pairs_per_group"] = fit.pairs_per_group;
  json pieces = json::array();
  for (const DragPiece& p : fit.pieces) pieces.push_back(PieceToJson(p));
  j["pieces"] = pieces;
  json points = json::array();
  for (const Eigen::Vector3d& p : fit.path.points) points.push_back({p.x(), p.y(), p.z()});
  j["path"] = {{"s_mm", fit.path.s_mm}, {"points", points}};
  if (with_series) {
    j["pair_s_mm"] = f.pair_s_mm;
    j["pair_mu"] = f.pair_mu;
    j["acf"] = fit.roughness.acf;
  }
  return j;
}

absl::StatusOr<TraceFit> TraceFitFromJson(const json& j) {
  if (!j.is_object()) return absl::InvalidArgumentError("fit must be a JSON object");
  TraceFit fit;
  FrictionFit& f = fit.friction;
  std::vector<double> normal, window;
  for (absl::Status s :
       {ReadKey(j, "mu", &f.mu), ReadKey(j, "mu_std", &f.mu_std), ReadKey(j, "mu_median", &f.mu_median),
        ReadKey(j, "normal", &normal), ReadKey(j, "n_pairs", &f.n_pairs), ReadKey(j, "window_mm", &window),
        ReadKey(j, "noise_std", &fit.noise_std), ReadKey(j, "path_length_mm", &fit.path_length_mm),
        ReadKey(j, "roughness_piece", &fit.roughness_piece), ReadKey(j, "pair_s_mm", &f.pair_s_mm),
        ReadKey(j, "pair_mu", &f.pair_mu), ReadKey(j, "acf", &fit.roughness.acf),
        ReadKey(j, "pairs_per_group", &fit.pairs_per_group)}) {
    if (!s.ok()) return s;
  }
  if (absl::Status s = GetRoughness(j, fit.roughness); !s.ok()) return s;
  if (fit.pairs_per_group < 1) {
    return absl::InvalidArgumentError(absl::StrCat("key 'pairs_per_group': ", fit.pairs_per_group, " must be >= 1"));
  }
  if (normal.size() == 3) f.normal = Eigen::Vector3d(normal[0], normal[1], normal[2]);
  if (window.size() == 2) {
    f.window_start_mm = window[0];
    f.window_end_mm = window[1];
  }
  // Fits stored before pieces existed have none of the keys below.
  if (auto it = j.find("changes"); it != j.end() && !it->is_null()) {
    if (!it->is_array()) return absl::InvalidArgumentError("key 'changes' must be an array");
    for (std::size_t i = 0; i < it->size(); ++i) {
      const json& c = (*it)[i];
      ChangePoint change;
      for (absl::Status s : {ReadKey(c, "s_mm", &change.s_mm), ReadKey(c, "pair", &change.index),
                             ReadKey(c, "statistic", &change.statistic),
                             ReadKey(c, "critical_value", &change.critical_value)}) {
        if (!s.ok()) return absl::Status(s.code(), absl::StrCat("changes[", i, "]: ", s.message()));
      }
      fit.changes.push_back(change);
    }
  }
  if (auto it = j.find("pieces"); it != j.end() && !it->is_null()) {
    if (!it->is_array()) return absl::InvalidArgumentError("key 'pieces' must be an array");
    for (std::size_t i = 0; i < it->size(); ++i) {
      absl::StatusOr<DragPiece> piece = PieceFromJson((*it)[i], i);
      if (!piece.ok()) return piece.status();
      fit.pieces.push_back(*std::move(piece));
    }
  }
  if (auto it = j.find("path"); it != j.end() && !it->is_null()) {
    std::vector<std::vector<double>> points;
    if (absl::Status s = ReadKey(*it, "s_mm", &fit.path.s_mm); !s.ok()) return absl::Status(s.code(), absl::StrCat("path: ", s.message()));
    if (absl::Status s = ReadKey(*it, "points", &points); !s.ok()) return absl::Status(s.code(), absl::StrCat("path: ", s.message()));
    if (points.size() != fit.path.s_mm.size()) {
      return absl::InvalidArgumentError(absl::StrCat("path: ", fit.path.s_mm.size(), " positions but ", points.size(), " points"));
    }
    for (std::size_t i = 0; i < points.size(); ++i) {
      if (points[i].size() != 3) return absl::InvalidArgumentError(absl::StrCat("path.points[", i, "] must hold 3 numbers"));
      fit.path.points.emplace_back(points[i][0], points[i][1], points[i][2]);
    }
  }
  return fit;
}

}  // namespace surfmap
