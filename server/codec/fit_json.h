// JSON forms of FitOptions and TraceFit. The same keys are used by
// `surfmap fit --json`, the fits stored in SQLite and the API's options_json,
// so a stored fit can be read back by any tool.
#pragma once

#include <string>

#include <nlohmann/json.hpp>
#include "absl/status/statusor.h"
#include "server/estimate/fit_trace.h"
#include "server/estimate/line_sample.h"

namespace surfmap {

// Estimator identity stored with every fit (provenance).
inline constexpr const char* kEstimatorName = "surfmap.differential+ar";
// Version 2: a fit carries its change points, pieces and path (line sample);
// version 1 fits read back without them. Version 3: a piece's roughness
// sigma is bias-corrected by the bootstrap like its coefficients (version 2
// kept the raw fit's implied process variance, which read a 5 mm rubber
// piece's sigma 27 % low); whole-drag fits are unchanged. Version 4: an end
// of a drag shorter than the split test's minimum piece is split off where
// the rest's AR(2) cannot have made it (change_points.h), and the stretch
// without it is searched again. Version 5: pairs closer than 0.1 mm (a rig
// faster than 100 Hz at 10 mm/s) are tested for changes in groups averaged
// to that spacing (pair_groups.h), and a pair's friction takes its sign
// from the motion over at least 0.1 mm (friction.cc); at 100 Hz fits are
// unchanged. Version 6: a piece's mu_se and effective_pairs of such a rig
// come from its pairs in those groups (drag_pieces.h); at 100 Hz unchanged.
// Version 7: where no single split is significant, a band inside the stretch
// (one model outside, another inside) is tested (change_points.h), so a
// drag across a low-contrast strip finds both its edges. Version 8: the
// pause's sensor noise is propagated through the pair normals to the
// roughness series (series_noise.h) and removed with its autocovariance; the
// white model before it subtracted about twice the noise the series carries,
// so weak textures read smoother than they are (ABS a1 1.07 for 0.90).
// Version 9 (FitOptions::series, force_variation.h): the roughness series
// reads each force against the pair normals averaged over +-0.5 mm, not its
// own pair's bisector, which carried half the difference between the forward
// texture and the reverse one interpolated between samples, so every texture
// read smoother than it is (sandpaper a1 0.34 for 0.30); and each pass's
// series is its own samples one step apart, not the nearest sample to each
// point of a fixed grid, which took a sample twice and skipped the next where
// the rig's speed wandered (masonite read less resonant).
inline constexpr const char* kEstimatorVersion = "9";

nlohmann::json FitOptionsToJson(const FitOptions& options);
// Missing keys keep their defaults; unknown keys and wrong types are errors.
absl::StatusOr<FitOptions> FitOptionsFromJson(const nlohmann::json& json);

// The flat summary: mu, mu_std, mu_median, normal[3], n_pairs, window_mm[2],
// a1..ap (as "a" array and a1/a2 keys), a_stderr, sigma, variance,
// stationary, reflection, acf_decay_mm, dominant_wavelength_mm (null when
// none), below_noise_floor, roughness_n, noise_std, path_length_mm,
// roughness_piece; the line sample: "changes" [{s_mm, pair, statistic,
// critical_value}], "pieces" [{start_mm, end_mm, first_pair, pairs,
// starts_at_change, ends_at_change, mu, mu_std, mu_median, mu_se,
// effective_pairs, roughness: "fitted"|"too_short"|"fit_failed",
// roughness_note?, fit?: {the roughness keys above}}], "path" {s_mm[],
// points[[x,y,z]]}. Per-pair arrays only when `with_series` (they are large).
// TraceFitFromJson reads fits without the line-sample keys (version 1) with
// no changes, pieces or path.
nlohmann::json TraceFitToJson(const TraceFit& fit, bool with_series = false);
absl::StatusOr<TraceFit> TraceFitFromJson(const nlohmann::json& json);

}  // namespace surfmap
