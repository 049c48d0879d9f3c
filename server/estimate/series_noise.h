// The sensor noise as it reaches a drag's roughness series.
//
// The force-variation series (force_variation.h) reads each sample's force
// against the normal estimated from that sample's own forward/reverse pair
// (friction.h). That normal takes up part of the noise, the reverse pass is
// interpolated between samples, and nearest-sample resampling can take one
// sample twice. So the noise on the series is neither the sensor's variance
// times (1 + mu^2) nor white: on a flat drag it is about half that at lag 0,
// with a lag-1 correlation, and a fit that subtracts the white model
// over-corrects a weak texture (ABS, process std 0.05 N: a1 1.07 for 0.90).
//
// Instead of a model, the noise is propagated: seeded replicates of white
// sensor noise of the pause's standard deviation are added to the forces, the
// pair normals and the series are recomputed exactly as for the fit, and the
// difference from the series without the replicate's noise is the noise's
// share of the series. The pipeline is linear in noise this small (0.015 N
// against 5 N contact forces), so the difference has the autocovariance of
// the noise already in the measured series.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "absl/status/statusor.h"
#include "server/estimate/data_window.h"
#include "server/estimate/drag_trace.h"
#include "server/estimate/force_variation.h"
#include "server/estimate/friction.h"
#include "server/estimate/path_pairing.h"

namespace surfmap {

// A stretch of the window with the friction coefficient its series is built
// with (a piece of the drag, or the whole window).
struct SeriesStretch {
  double start_mm = 0.0;
  double end_mm = 0.0;
  double mu = 0.0;
};

struct SeriesNoiseOptions {
  // Sensor noise per axis, N (PauseNoiseStd); 0 gives zero autocovariances.
  double noise_std = 0.0;
  double step_mm = 0.1;  // the series' grid step
  int max_lag = 2;       // lags 0..max_lag (the AR order)
  // Replicates pooled. 4: each lag from ~4 x 2 x 160 grid points on a 16 mm
  // window, a standard error of ~4 % of the lag-0 noise variance, which is
  // itself a tenth of a weak texture's variance.
  int replicates = 4;
  std::uint64_t seed = 1;
  SeriesOptions series;  // as the series the noise rides on is built
};

// Per stretch, the noise's autocovariance at lags 0..max_lag (N^2), pooled
// over the replicates and both passes, each lag averaged over its products.
// `friction` is the fit of the unperturbed passes over `window`. Errors:
// INVALID_ARGUMENT for replicates outside 1..64, max_lag outside 0..20, a
// stretch whose series cannot be built (force_variation.h), or a replicate
// whose friction fit fails (a contact force so close to the floor that the
// noise crosses it).
absl::StatusOr<std::vector<std::vector<double>>> PropagateSeriesNoise(
    std::span<const DragSample> forward, std::span<const DragSample> reverse, const PathPairing& pairing,
    const DataWindow& window, const FrictionOptions& friction_options, const FrictionFit& friction,
    std::span<const SeriesStretch> stretches, const SeriesNoiseOptions& options);

}  // namespace surfmap
