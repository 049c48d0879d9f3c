// FitTrace: friction and roughness from one drag trace.
//
// Steps (each its own file): SplitDragPasses (drag_passes.h) -> PairPasses by
// arc length (path_pairing.h) -> ChooseDataWindow (data_window.h) ->
// FitFriction, the differential method (friction.h) -> ForceVariationSeries
// and PauseNoiseStd (force_variation.h) -> FitAutoregressive (roughness.h).
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>
#include "absl/status/statusor.h"
#include "server/estimate/data_window.h"
#include "server/estimate/drag_trace.h"
#include "server/estimate/friction.h"
#include "server/estimate/path_pairing.h"
#include "server/estimate/roughness.h"
#include "server/estimate/texture.h"

namespace surfmap {

struct FitOptions {
  double step_mm = 0.1;           // roughness grid step L
  int ar_order = 2;
  ArMethod ar_method = ArMethod::kBurg;
  // Use the pause to de-bias roughness: the variance of the sensor noise on
  // the roughness series (see FitTrace) goes to ArFitOptions::noise_variance.
  bool noise_aware = true;
  // Data window: keep where both passes move at >= min_speed_fraction of their
  // median speed, intersected with the common forward/reverse path minus
  // window_trim_fraction of it at each end (see data_window.h for why).
  double min_speed_fraction = 0.7;
  double window_trim_fraction = 0.1;
  int min_pass_samples = 10;      // per pass, before any windowing
  PairingOptions pairing;         // retrace limits
  FrictionOptions friction;       // contact force floor, minimum pairs
  bool IsValid(std::string* why) const;
};

// FrictionFit is declared in friction.h.

struct TraceFit {
  FrictionFit friction;
  ArFit roughness;
  double noise_std = 0.0;         // force noise during the pause, N (PauseNoiseStd)
  double path_length_mm = 0.0;    // forward path length
  double max_retrace_offset_mm = 0.0;  // largest reverse-to-forward path distance
};

// Errors (INVALID_ARGUMENT, message naming the problem and the sample): no
// forward or reverse pass, phases out of order, non-finite values, positions
// or forces beyond 1e9 mm or N (see drag_passes.h), time not
// increasing, too few samples, a reverse pass that does not retrace the
// forward path, a contact force below the floor ("zero force"), an empty data
// window, invalid options; a roughness fit that fails comes back with
// "roughness fit: " before FitAutoregressive's message.
//
// Roughness: FitAutoregressive on the two segments of ForceVariationSeries
// (forward and reverse pass); with noise_aware the noise variance passed on
// is noise_std^2 * (1 + mu^2): the variation |f_t| - mu f_n carries the
// tangential noise plus mu times the normal noise.
absl::StatusOr<TraceFit> FitTrace(const DragTrace& trace, const FitOptions& options);

// What the sampling plan and the map take from a fit: mu and its spread, and
// the roughness model only when it is stationary (an unstable model has no
// valid reflection coefficients; leaving it out keeps it from poisoning the map).
TextureParams TextureOf(const TraceFit& fit);

}  // namespace surfmap
