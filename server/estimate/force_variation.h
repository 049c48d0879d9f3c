// The roughness input of a drag: the force variation about the Coulomb
// nominal, on a uniform arc-length grid, and the sensor noise floor.
#pragma once

#include <span>

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
// Each pass is resampled (linear interpolation) on the grid
// window_start + k * step_mm and detrended (least-squares line removed); the
// result is the mean of the two passes at each grid point. The reverse pass
// feels the same realisation of the texture, so it is not independent data:
// averaging keeps the texture and halves the noise variance.
// INVALID_ARGUMENT when the window holds fewer than 2 grid points.
absl::StatusOr<Eigen::VectorXd> ForceVariationSeries(std::span<const DragSample> forward,
                                                     std::span<const DragSample> reverse,
                                                     const PathPairing& pairing,
                                                     const FrictionFit& friction, double step_mm);

// Standard deviation of the force during the pause, per axis after removing a
// least-squares line in time (the residual tangential force relaxes), combined
// as sqrt(mean of the three variances); N. 0 when the pause has < 3 samples.
double PauseNoiseStd(std::span<const DragSample> pause);

}  // namespace surfmap
