// FitTrace: friction and roughness from one drag trace.
//
// Steps (each its own file): SplitDragPasses (drag_passes.h) -> PairPasses by
// arc length (path_pairing.h) -> ChooseDataWindow (data_window.h) ->
// FitFriction, the differential method (friction.h) -> DetectChangePoints in
// the per-pair mu (change_points.h) -> CutDragPieces (drag_pieces.h) ->
// ForceVariationSeries per piece and PauseNoiseStd (force_variation.h) ->
// FitAutoregressive (roughness.h).
//
// A drag is a line sample: the pieces (each a pure stretch of one material,
// with its extent along the path) and the path itself (`path`, positions of
// the window every path_step_mm) are what a map needs; the headline mu is
// the mean over the whole window, a blend when the drag crossed a boundary.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>
#include "absl/status/statusor.h"
#include "server/estimate/change_points.h"
#include "server/estimate/data_window.h"
#include "server/estimate/drag_pieces.h"
#include "server/estimate/drag_trace.h"
#include "server/estimate/force_variation.h"
#include "server/estimate/friction.h"
#include "server/estimate/path_pairing.h"
#include "server/estimate/roughness.h"
#include "server/estimate/texture.h"

namespace surfmap {

struct FitOptions {
  double step_mm = 0.1;           // roughness grid step L
  int ar_order = 2;
  ArMethod ar_method = ArMethod::kBurg;
  // Use the pause to de-bias roughness: the sensor noise measured in the
  // pause is propagated to the roughness series (series_noise.h) and its
  // autocovariance goes to ArFitOptions::noise_autocovariance.
  bool noise_aware = true;
  // Replicates of that propagation (SeriesNoiseOptions::replicates), 0..64;
  // 0 = not propagated: the white model noise_std^2 (1 + mu^2) of estimator
  // version 7, kept for comparison.
  int noise_replicates = 4;
  // The normal each sample's force is read against for the roughness series
  // (force_variation.h): pair normals averaged along the path; halfwidth 0
  // is each pair's own normal, estimator version 8.
  SeriesOptions series;
  // Data window: keep where both passes move at >= min_speed_fraction of their
  // median speed, intersected with the common forward/reverse path minus
  // window_trim_fraction of it at each end (see data_window.h for why).
  double min_speed_fraction = 0.7;
  double window_trim_fraction = 0.1;
  int min_pass_samples = 10;      // per pass, before any windowing
  PairingOptions pairing;         // retrace limits
  FrictionOptions friction;       // contact force floor, minimum pairs
  ChangePointOptions changes;     // material changes inside a drag
  // A piece gets its own roughness fit only when its extent (less the guard
  // at each change) is at least this long. Why 5 mm: at the 0.1 mm grid that
  // is 50 points per pass; the AR(2) coefficients' standard error is then
  // about sqrt((1 - a2^2) / n) <= 0.1 (both passes, which feel the same
  // texture, count once), enough to tell the paper's textures apart (rubber
  // a1 0.6, masonite 1.61, sandpaper 0.3) and to pool into a map. Shorter
  // pieces are flagged kTooShort, never fitted with their neighbours.
  double min_roughness_piece_mm = 5.0;
  // Left out of a piece's roughness series next to a change point: the change
  // is located to about one pair spacing (0.1 mm) and the texture on the
  // other side must not leak into the fit.
  double change_guard_mm = 0.3;
  // Replicates of the small-sample bias correction of a piece's roughness fit
  // (ArFitOptions::bias_replicates, ar_bias_correction.h); 0 = off. Only the
  // pieces of a drag that crossed a change: they are short (5-10 mm, a2 low
  // by 0.05-0.1 uncorrected); a one-piece drag's window (~16 mm) loses ~0.02,
  // a third of its standard error, and keeps FitTrace's speed. 64 replicates:
  // Monte-Carlo error ~0.012 on a 5 mm rubber piece, ~0.6 ms per piece.
  int piece_bias_replicates = 64;
  // Spacing of TraceFit::path (positions of the window along the forward
  // path): a 20 mm drag on a 40 mm radius has a chord error of 0.003 mm at 1 mm.
  double path_step_mm = 1.0;
  bool IsValid(std::string* why) const;
};

// Positions of the forward path over the data window: s_mm[i] (mm from the
// forward path's first sample, the frame of FrictionFit::window_* and
// DragPiece) and points[i] (mm, the trace's frame). Both window ends are
// included; interior points every FitOptions::path_step_mm.
struct DragPathSamples {
  std::vector<double> s_mm;
  std::vector<Eigen::Vector3d> points;
};

// FrictionFit is declared in friction.h.

struct TraceFit {
  FrictionFit friction;
  // The roughness of the drag: the whole window's fit when no change was
  // detected; otherwise the fit of the longest piece that has one (index in
  // roughness_piece), never a fit across a change; empty (a = {}, stationary
  // false, roughness_piece -1) when no piece could be fitted.
  ArFit roughness;
  int roughness_piece = 0;
  std::vector<ChangePoint> changes;  // detected in friction.pair_mu, in path order
  // The pairs were tested in groups of this many (pair_groups.h:
  // ChangePointOptions::group_spacing_mm over their spacing; 1 at 100 Hz);
  // pieces leave out this many pairs next to each change.
  int pairs_per_group = 1;
  std::vector<DragPiece> pieces;     // changes.size() + 1 pieces covering the window
  DragPathSamples path;
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
// (forward and reverse pass); with noise_aware the pause's noise propagated
// to that series (series_noise.h, seeded from the trace's own data, so a refit
// gives the same answer) is passed on as its autocovariance. Should the
// propagation fail (a replicate's noise taking a contact force below the
// floor), the white model noise_std^2 * (1 + mu^2) is passed instead: the
// variation |f_t| - mu f_n carries the tangential noise plus mu times the
// normal noise, were the normal known. With one piece a failing
// roughness fit is an error (as above); with several, each piece's fit is its
// own, and a piece whose fit fails is marked kFitFailed with the reason.
absl::StatusOr<TraceFit> FitTrace(const DragTrace& trace, const FitOptions& options);

// What the sampling plan and the map take from a fit: mu and its spread, and
// the roughness model only when it is stationary (an unstable model has no
// valid reflection coefficients; leaving it out keeps it from poisoning the map).
TextureParams TextureOf(const TraceFit& fit);

}  // namespace surfmap
