// The roughness input of a drag: the force variation about the Coulomb
// nominal, on a uniform arc-length grid, and the sensor noise floor.
#pragma once

#include <span>
#include <string>
#include <vector>

#include <Eigen/Core>
#include "absl/status/statusor.h"
#include "server/estimate/drag_trace.h"
#include "server/estimate/friction.h"
#include "server/estimate/path_pairing.h"

namespace surfmap {

// How the roughness series is read from the samples.
//
// The normal: each sample's force is read against the pair normals
// (friction.h) averaged over a short stretch of the path. A pair normal is
// the bisector of the forward force and the reverse force interpolated at the
// same arc length, and the two passes' samples never fall at the same places
// on a real rig: the reverse texture interpolated between two samples is not
// the forward sample's, the difference tilts the bisector, and a series read
// against that pair's own normal keeps only about half the forward sample's
// texture, averaged with its smoothed reverse. A flat sandpaper drag with the
// simulated rig's 3 % speed jitter alone read a1 0.34 for 0.30 (ideal rig,
// samples of both passes at the same places: 0.27), rubber and every other
// texture alike (estimator version 8). The surface's own normal turns over
// millimetres, the texture's tilt changes every sample, so an average over
// +-halfwidth_mm keeps the one and removes the other.
//
// The samples: see follow_samples.
struct SeriesOptions {
  // Half-width of the average along the path, mm; 0: each pair's own normal
  // (estimator version 8). Symmetric about the sample (narrowed near the
  // ends of the pairs), so a normal turning steadily along the path is not
  // biased. 0.5: ~10 pairs at the 0.1 mm spacing, and the normal of a 5 mm
  // radius turns by 6 degrees across it.
  double halfwidth_mm = 0.5;
  // Only pair normals within this angle of the sample's own pair normal join
  // its average, so over a sharp edge (a CAD part's facets) the faces'
  // normals are not blended. 5 degrees: a texture tilts the bisector by
  // about (texture difference) / (2 Fn): sandpaper's 0.3 N at 5 N, 2 degrees.
  double max_turn_deg = 5.0;
  // true: each pass's series is its own samples in order, one every step_mm
  // or as near as the samples allow (every sample of a probe sampling about
  // once per step, every n-th of a faster one), none taken twice. false: the
  // value at each point of the grid start + k * step_mm is the nearest
  // sample's (estimator version 8). Where the rig's speed wanders,
  // the grid drifts across the samples, and where it falls halfway between
  // two of them it takes one twice and skips the next: a resonant texture
  // (masonite, a1 1.61) then reads rougher and less resonant than it is.
  bool follow_samples = true;
  bool IsValid(std::string* why) const;
};

// Per sample of each pass inside the friction window: |f_t| - mu * f_n with
// f_n = f . n and f_t = f - f_n n, n the LOCAL normal (SeriesOptions,
// interpolated at the sample's arc length) and mu the fitted friction.
// Normal-force changes (force-control transients, vibration) scale friction
// too, so they cancel here; what is left is texture plus sensor noise.
// Each pass is read at about step_mm (SeriesOptions::follow_samples; never
// by linear interpolation, which at drifting fractional offsets would
// low-pass the texture and bias the AR fit towards a smoother process) and
// detrended (least-squares line removed). Returns two segments, forward then
// reverse, both increasing in arc length, for the multi-segment
// FitAutoregressive. They see the same realisation of the texture (so they
// are not independent data), with independent noise. INVALID_ARGUMENT when
// the window holds fewer than 2 grid points or more than
// kMaxRoughnessGridPoints, or a pass fewer than 2 samples in it.
// 4M points (32 MB per series): a 419 m window at the default 0.1 mm step,
// far beyond any drag, and an int with room to spare.
inline constexpr int kMaxRoughnessGridPoints = 1 << 22;

absl::StatusOr<std::vector<Eigen::VectorXd>> ForceVariationSeries(std::span<const DragSample> forward,
                                                     std::span<const DragSample> reverse,
                                                     const PathPairing& pairing,
                                                     const FrictionFit& friction, double step_mm,
                                                     const SeriesOptions& series);

// The same over the stretch start_mm..end_mm of the path (inside the friction
// window) with friction coefficient `mu`: the series of one piece of a drag
// (drag_pieces.h), so that no roughness fit spans a change of material.
absl::StatusOr<std::vector<Eigen::VectorXd>> ForceVariationSeries(std::span<const DragSample> forward,
                                                     std::span<const DragSample> reverse,
                                                     const PathPairing& pairing,
                                                     const FrictionFit& friction, double start_mm,
                                                     double end_mm, double mu, double step_mm,
                                                     const SeriesOptions& series);

// The values `val` of one pass, at arc lengths `pos` (increasing), read one
// every `step` from `start` to `end` (SeriesOptions::follow_samples). Empty
// when there are no samples, step is not > 0, end < start, or the window
// holds kMaxRoughnessGridPoints steps or more.
std::vector<double> ReadAtStep(const std::vector<double>& pos, const std::vector<double>& val, double start,
                               double end, double step, bool follow_samples);

// The normals of SeriesOptions (halfwidth_mm, max_turn_deg), one per pair of
// `friction` (unit).
std::vector<Eigen::Vector3d> SeriesNormals(const FrictionFit& friction, const SeriesOptions& options);

// White sensor noise of the force during the pause, N: per axis the
// standard deviation of first differences over sqrt(2), combined as
// sqrt(mean of the three variances). Differencing detrends: the residual
// tangential force relaxing and the force controller's slow wander (which a
// straight line does not remove) drop out, white noise stays. 0 when the
// pause has < 3 samples.
double PauseNoiseStd(std::span<const DragSample> pause);

}  // namespace surfmap
