#include "server/estimate/fit_trace.h"

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"
#include "server/estimate/drag_passes.h"
#include "server/estimate/force_variation.h"

namespace surfmap {

bool FitOptions::IsValid(std::string* why) const {
  auto fail = [&](std::string message) {
    if (why) *why = std::move(message);
    return false;
  };
  if (!(step_mm > 0.0)) return fail("step_mm must be > 0");
  if (ar_order < 1) return fail("ar_order must be >= 1");
  if (min_pass_samples < 2) return fail("min_pass_samples must be >= 2");
  std::string inner;
  WindowOptions window{min_speed_fraction, WindowOptions{}.smoothing_s, window_trim_fraction};
  if (!window.IsValid(&inner)) return fail(inner);
  if (!pairing.IsValid(&inner)) return fail(absl::StrCat("pairing: ", inner));
  if (!friction.IsValid(&inner)) return fail(absl::StrCat("friction: ", inner));
  return true;
}

absl::StatusOr<TraceFit> FitTrace(const DragTrace& trace, const FitOptions& options) {
  std::string why;
  if (!options.IsValid(&why)) return absl::InvalidArgumentError(absl::StrCat("FitOptions: ", why));
  absl::StatusOr<DragPasses> passes = SplitDragPasses(trace);
  if (!passes.ok()) return passes.status();
  const auto& [forward, pause, reverse, pause_offset, reverse_offset] = *passes;
  if (static_cast<int>(forward.size()) < options.min_pass_samples ||
      static_cast<int>(reverse.size()) < options.min_pass_samples) {
    return absl::InvalidArgumentError(absl::StrCat(
        "too few samples: forward pass ", forward.size(), ", reverse pass ", reverse.size(),
        "; a fit needs at least ", options.min_pass_samples, " in each"));
  }

  absl::StatusOr<PathPairing> pairing = PairPasses(forward, reverse, options.pairing);
  if (!pairing.ok()) return pairing.status();
  WindowOptions window_options;
  window_options.min_speed_fraction = options.min_speed_fraction;
  window_options.trim_fraction = options.window_trim_fraction;
  absl::StatusOr<DataWindow> window = ChooseDataWindow(forward, reverse, *pairing, window_options);
  if (!window.ok()) return window.status();

  TraceFit fit;
  absl::StatusOr<FrictionFit> friction =
      FitFriction(forward, reverse, *pairing, *window, options.friction);
  if (!friction.ok()) return friction.status();
  fit.friction = *std::move(friction);
  fit.path_length_mm = pairing->path_length_mm;
  fit.max_retrace_offset_mm = pairing->max_offset_mm;
  fit.noise_std = PauseNoiseStd(pause);

  absl::StatusOr<std::vector<Eigen::VectorXd>> series =
      ForceVariationSeries(forward, reverse, *pairing, fit.friction, options.step_mm);
  if (!series.ok()) return series.status();
  ArFitOptions ar;
  ar.order = options.ar_order;
  ar.method = options.ar_method;
  ar.step_mm = options.step_mm;
  if (options.noise_aware) {
    const double mu = fit.friction.mu;
    ar.noise_variance = fit.noise_std * fit.noise_std * (1.0 + mu * mu);
  }
  absl::StatusOr<ArFit> roughness = FitAutoregressive(*series, ar);
  if (!roughness.ok()) {
    return absl::Status(roughness.status().code(),
                        absl::StrCat("roughness fit: ", roughness.status().message()));
  }
  fit.roughness = *std::move(roughness);
  return fit;
}

TextureParams TextureOf(const TraceFit& fit) {
  TextureParams t;
  t.mu = fit.friction.mu;
  t.mu_std = fit.friction.mu_std;
  if (fit.roughness.stationary) {
    t.reflection = fit.roughness.reflection;
    t.sigma = fit.roughness.sigma;
  }
  return t;
}

}  // namespace surfmap
