// The pieces of a drag: the stretches of the per-pair friction series between
// detected change points (change_points.h), each a pure sample of one
// material along its extent of the path.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "absl/status/statusor.h"
#include "server/estimate/change_points.h"
#include "server/estimate/friction.h"
#include "server/estimate/roughness.h"

namespace surfmap {

enum class PieceRoughness {
  kFitted,     // `roughness` holds the piece's own AR fit
  kTooShort,   // shorter than the minimum for a roughness fit: not fitted (never fitted across a change)
  kFitFailed,  // long enough, but the AR fit failed (`roughness_note` says why)
};
std::string_view PieceRoughnessName(PieceRoughness state);  // "fitted", "too_short", "fit_failed"

struct DragPiece {
  // Pairs first_pair .. first_pair + pair_count - 1 of the FrictionFit (the
  // transitional pairs next to each change, CutDragPieces' guard_pairs, are
  // left out).
  int first_pair = 0;
  int pair_count = 0;
  // Extent along the forward path (mm from its first sample, the frame of
  // FrictionFit::window_*): from the window start or a change point to a
  // change point or the window end.
  double start_mm = 0.0;
  double end_mm = 0.0;
  bool starts_at_change = false;
  bool ends_at_change = false;
  double mu = 0.0;          // mean of the per-pair mu
  double mu_std = 0.0;      // their sample standard deviation (the texture's spread, not an error)
  double mu_median = 0.0;
  // Standard error of mu, sqrt(inflation * mu_std^2 / pair_count), and the
  // independent pairs credited, pair_count / inflation. The variance
  // inflation is the larger of the pairs' modelled serial correlation
  // (SeriesDependence::mean_inflation, series_dependence.h: neighbouring pairs
  // feel the same texture) and the cap's, pair_count / (kMaxIndependentPairsPerMm
  // x the pairs' extent in mm, at least 1), clamped to 1..pair_count. Where
  // the pairs were grouped (pairs_per_group > 1) all of this is of the
  // groups: group count for pair_count, the groups' variance for mu_std^2.
  double mu_se = 0.0;
  double effective_pairs = 0.0;  // pair_count / inflation (the capped one above)
  PieceRoughness roughness_state = PieceRoughness::kTooShort;
  std::string roughness_note;    // why not fitted (empty when fitted)
  ArFit roughness;               // when kFitted
  double length_mm() const { return end_mm - start_mm; }
};

// A piece is never credited with more than this many independent pairs per
// mm of path: the coarsest texture of the paper's family (rubber, AR(2) root
// 0.88 on the 0.1 mm grid) is correlated over ~0.8 mm, so one independent
// value per 1.6 mm. An AR(2) fitted to a few mm of pairs sees much less of
// that correlation than there is (and the sensor noise on top makes it look
// whiter), and a standard error from it alone can be 2-4x too small.
inline constexpr double kMaxIndependentPairsPerMm = 1.0 / 1.6;

// The pieces of `friction`'s per-pair series cut at `changes` (indices into
// the series, increasing), with their friction statistics; roughness is left
// kTooShort for FitTrace to fill in. `guard_pairs` pairs each side of a
// change belong to neither piece (the change was found in groups of that
// many pairs, pair_groups.h). With `pairs_per_group` k > 1 (a rig faster
// than the texture's 0.1 mm grid) mu_se and effective_pairs come from the
// piece's pairs averaged in groups of k, so a piece is credited the same
// precision whatever the rig's sample rate. Errors (INVALID_ARGUMENT): an empty series,
// change indices out of order or out of range, or so close that a piece
// keeps fewer than 2 pairs.
absl::StatusOr<std::vector<DragPiece>> CutDragPieces(const FrictionFit& friction,
                                                     const std::vector<ChangePoint>& changes,
                                                     int guard_pairs = kChangeGuardPairs, int pairs_per_group = 1);

}  // namespace surfmap
