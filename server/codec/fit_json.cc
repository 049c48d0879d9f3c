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

}  // namespace

json FitOptionsToJson(const FitOptions& o) {
  return json{{"step_mm", o.step_mm},
              {"ar_order", o.ar_order},
              {"ar_method", ArMethodName(o.ar_method)},
              {"noise_aware", o.noise_aware},
              {"window_trim_fraction", o.window_trim_fraction}};
}

absl::StatusOr<FitOptions> FitOptionsFromJson(const json& j) {
  if (!j.is_object()) return absl::InvalidArgumentError("estimator options must be a JSON object");
  static const std::set<std::string> kKnown = {"step_mm", "ar_order", "ar_method", "noise_aware",
                                               "window_trim_fraction"};
  for (auto it = j.begin(); it != j.end(); ++it) {
    if (!kKnown.count(it.key())) return absl::InvalidArgumentError(absl::StrCat("unknown estimator option '", it.key(), "'"));
  }
  FitOptions o;
  std::string method = ArMethodName(o.ar_method);
  for (absl::Status s : {ReadKey(j, "step_mm", &o.step_mm), ReadKey(j, "ar_order", &o.ar_order),
                         ReadKey(j, "ar_method", &method), ReadKey(j, "noise_aware", &o.noise_aware),
                         ReadKey(j, "window_trim_fraction", &o.window_trim_fraction)}) {
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
  const ArFit& r = fit.roughness;
  json j{{"mu", f.mu},
         {"mu_std", f.mu_std},
         {"mu_median", f.mu_median},
         {"normal", {f.normal.x(), f.normal.y(), f.normal.z()}},
         {"n_pairs", f.n_pairs},
         {"window_mm", {f.window_start_mm, f.window_end_mm}},
         {"a", r.a},
         {"a_stderr", r.a_stderr},
         {"a1", r.a.size() > 0 ? json(r.a[0]) : json(nullptr)},
         {"a2", r.a.size() > 1 ? json(r.a[1]) : json(nullptr)},
         {"sigma", r.sigma},
         {"variance", r.variance},
         {"stationary", r.stationary},
         {"reflection", r.reflection},
         {"acf_decay_mm", r.acf_decay_mm},
         {"dominant_wavelength_mm", OptionalNumber(r.dominant_wavelength_mm)},
         {"below_noise_floor", r.below_noise_floor},
         {"roughness_n", r.n},
         {"noise_std", fit.noise_std},
         {"path_length_mm", fit.path_length_mm}};
  if (with_series) {
    j["pair_s_mm"] = f.pair_s_mm;
    j["pair_mu"] = f.pair_mu;
    j["acf"] = r.acf;
  }
  return j;
}

absl::StatusOr<TraceFit> TraceFitFromJson(const json& j) {
  if (!j.is_object()) return absl::InvalidArgumentError("fit must be a JSON object");
  TraceFit fit;
  FrictionFit& f = fit.friction;
  ArFit& r = fit.roughness;
  std::vector<double> normal, window;
  std::optional<double> wavelength;
  if (auto it = j.find("dominant_wavelength_mm"); it != j.end() && it->is_number()) wavelength = it->get<double>();
  for (absl::Status s :
       {ReadKey(j, "mu", &f.mu), ReadKey(j, "mu_std", &f.mu_std), ReadKey(j, "mu_median", &f.mu_median),
        ReadKey(j, "normal", &normal), ReadKey(j, "n_pairs", &f.n_pairs), ReadKey(j, "window_mm", &window),
        ReadKey(j, "a", &r.a), ReadKey(j, "a_stderr", &r.a_stderr), ReadKey(j, "sigma", &r.sigma),
        ReadKey(j, "variance", &r.variance), ReadKey(j, "stationary", &r.stationary),
        ReadKey(j, "reflection", &r.reflection), ReadKey(j, "acf_decay_mm", &r.acf_decay_mm),
        ReadKey(j, "below_noise_floor", &r.below_noise_floor), ReadKey(j, "roughness_n", &r.n),
        ReadKey(j, "noise_std", &fit.noise_std), ReadKey(j, "path_length_mm", &fit.path_length_mm),
        ReadKey(j, "pair_s_mm", &f.pair_s_mm), ReadKey(j, "pair_mu", &f.pair_mu), ReadKey(j, "acf", &r.acf)}) {
    if (!s.ok()) return s;
  }
  if (normal.size() == 3) f.normal = Eigen::Vector3d(normal[0], normal[1], normal[2]);
  if (window.size() == 2) {
    f.window_start_mm = window[0];
    f.window_end_mm = window[1];
  }
  r.dominant_wavelength_mm = wavelength;
  return fit;
}

}  // namespace surfmap
