// JSON forms of FitOptions and TraceFit. The same keys are used by
// `surfmap fit --json`, the fits stored in SQLite and the API's options_json,
// so a stored fit can be read back by any tool.
#pragma once

#include <string>

#include <nlohmann/json.hpp>
#include "absl/status/statusor.h"
#include "server/estimate/fit_trace.h"

namespace surfmap {

// Estimator identity stored with every fit (provenance).
inline constexpr const char* kEstimatorName = "surfmap.differential+ar";
inline constexpr const char* kEstimatorVersion = "1";

nlohmann::json FitOptionsToJson(const FitOptions& options);
// Missing keys keep their defaults; unknown keys and wrong types are errors.
absl::StatusOr<FitOptions> FitOptionsFromJson(const nlohmann::json& json);

// The flat summary: mu, mu_std, mu_median, normal[3], n_pairs, window_mm[2],
// a1..ap (as "a" array and a1/a2 keys), a_stderr, sigma, stationary,
// reflection, acf_decay_mm, dominant_wavelength_mm (null when none),
// below_noise_floor, noise_std, path_length_mm. Per-pair arrays only when
// `with_series` (they are large).
nlohmann::json TraceFitToJson(const TraceFit& fit, bool with_series = false);
absl::StatusOr<TraceFit> TraceFitFromJson(const nlohmann::json& json);

}  // namespace surfmap
