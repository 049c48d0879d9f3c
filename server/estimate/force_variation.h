// The roughness input of a drag: the force variation about the Coulomb
// nominal, on a uniform arc-length grid, and the sensor noise floor.
#pragma once

#include <span>
#include <vector>

#include <Eigen/Core>
#include "absl/status/statusor.h"
#include "server/estimate/drag_trace.h"
#include "server/estimate/friction.h"
#include "server/estimate/path_pairing.h"

namespace surfmap {

// Per sample of each pass inside the friction window: |f_t| - mu * f_n with
// f_n = f . n and f_t = f - f_n n, n the LOCAL normal from the pairing
// (interpolated at the sample's arc length) and mu the fitted friction.
// Normal-force changes (force-control transients, vibration) scale friction
// too, so they cancel here; what is left is texture plus sensor noise.
// Each pass is resampled on the grid window_start + k * step_mm by taking the
// nearest sample (the probe samples about once per grid step; linear
// interpolation at drifting fractional offsets would low-pass the texture and
// bias the AR fit towards a smoother process) and detrended (least-squares
// line removed). Returns two segments, forward then reverse, both increasing
// in arc length, for the multi-segment FitAutoregressive. They see the same
// realisation of the texture (so they are not independent data), with
// independent noise. INVALID_ARGUMENT when the window holds fewer than 2 grid
// points or more than kMaxRoughnessGridPoints.
// 4M points (32 MB per series): a 419 m window at the default 0.1 mm step,
// far beyond any drag, and an int with room to spare.
inline constexpr int kMaxRoughnessGridPoints = 1 << 22;

absl::StatusOr<std::vector<Eigen::VectorXd>> ForceVariationSeries(std::span<const DragSample> forward,
                                                     std::span<const DragSample> reverse,
                                                     const PathPairing& pairing,
                                                     const FrictionFit& friction, double step_mm);

// The same over the stretch start_mm..end_mm of the path (inside the friction
// window) with friction coefficient `mu`: the series of one piece of a drag
// (drag_pieces.h), so that no roughness fit spans a change of material.
absl::StatusOr<std::vector<Eigen::VectorXd>> ForceVariationSeries(std::span<const DragSample> forward,
                                                     std::span<const DragSample> reverse,
                                                     const PathPairing& pairing,
                                                     const FrictionFit& friction, double start_mm,
                                                     double end_mm, double mu, double step_mm);

// White sensor noise of the force during the pause, N: per axis the
// standard deviation of first differences over sqrt(2), combined as
// sqrt(mean of the three variances). Differencing detrends: the residual
// tangential force relaxing and the force controller's slow wander (which a
// straight line does not remove) drop out, white noise stays. 0 when the
// pause has < 3 samples.
double PauseNoiseStd(std::span<const DragSample> pause);

}  // namespace surfmap
