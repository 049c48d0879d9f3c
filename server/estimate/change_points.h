// Change points in a drag's per-pair friction series: where the probe crossed
// from one material into another. A drag is a line sample: the per-pair mu
// along the path shows a boundary's position to a fraction of a mm, and a
// drag that straddles two materials must not be reported as one blended value.
//
// Method: binary segmentation with a likelihood-ratio test for a change of
// the series' AR(2) model. The per-pair friction rides on the surface
// texture, which the method models as an AR(2) process in space (docs/method.md
// section 3); within one material the series is that process about the
// material's mu, with the sensor's noise. A material change changes the mean
// (mu), the texture's correlation (a1, a2) and its amplitude (innovation
// variance), or some of them. So, in a stretch [a, b) of the series, for every
// split k leaving at least `min_piece_mm` and `min_piece_pairs` on each side:
//
//   LR(k) = N log(RSS / N) - N1 log(RSS1 / N1) - N2 log(RSS2 / N2)
//
// with RSS1, RSS2 the residual sums of squares of least-squares AR(2) fits
// with intercept, x_t = c + a1 x_(t-1) + a2 x_(t-2) + e_t, on the rows of each
// side (N1, N2 rows; no row's lags reach across k) and RSS of one fit on the
// same rows together. The innovations of a correct model are white, so no
// correction for the texture's correlation is needed (a test of the raw mean
// would see changes everywhere: neighbouring pairs feel the same texture). At
// a fixed k, LR is asymptotically chi-square with 4 degrees of freedom under
// "no change"; the split is placed at the largest LR and kept when that
// exceeds the Bonferroni critical value over the stretch's candidates at the
// family-wise false-alarm probability (conservative: neighbouring candidates
// are strongly correlated). Where no split is kept, a band is tested: one
// model on [k1, k2), another on the rest of the stretch (a drag across a
// strip; each side of any single split would hold both materials), the same
// LR with 4 degrees of freedom over every allowed (k1, k2), Bonferroni over
// those. Both sides (all three pieces) are then searched again. At the end
// every change is re-placed at the largest LR within the stretch between its
// neighbouring changes.
//
// The drag's two ends are too short for that test where they hold less
// than the minimum piece of another material (the window starts or ends just
// past a boundary), and such an end's jump sits in the fits of its stretch
// and can hide a change inside it. So the series without its untestable
// ends is fitted, the fit predicts the end's values one by one (backwards
// at the start: an AR process's covariance is the same both ways in time),
// and an end is split off where a value's standardised residual exceeds the
// two-sided normal quantile at half the false-alarm probability over every
// value tested at both ends, the values from there on having moved the same
// way by at least half of it (a lone spike does not). Where no end is split
// off so, the series is segmented and the same is tried with the stretches
// before the first change and after the last as the rest (the other half
// of the probability). The series without the ends split off is then
// segmented again.
#pragma once

#include <span>
#include <string>
#include <vector>

#include "absl/status/statusor.h"

namespace surfmap {

// The pair on each side of a change is transitional: its reverse force is
// interpolated between reverse samples that may lie on both sides of the
// boundary (0.1 mm apart), so it can hold a blend of the two materials. It
// belongs to neither piece's statistics nor to the stretches searched after
// the change is found.
inline constexpr int kChangeGuardPairs = 1;

struct ChangePointOptions {
  // Family-wise false-alarm probability per drag, spent by the split test and
  // again by the band test where no split is kept (change_points_rates_benchmark
  // measures what both together fire). A map takes ~100-200 drags;
  // at 1e-3 a whole map expects ~0.1-0.2 false changes, and a false change
  // only splits a drag into two pieces that the map then finds alike.
  double false_alarm_probability = 1e-3;
  // Shortest piece, mm along the path: a side's AR(2) fit needs a few
  // correlation lengths of texture (masonite's is correlated over ~0.6 mm);
  // 1.5 mm holds ~15 pairs at the paper's 10 mm/s and 100 Hz. Shorter
  // stretches at a drag's ends are never split off (they stay in the piece
  // next to them).
  double min_piece_mm = 1.5;
  // ... and never fewer pairs than this on a side, whatever their spacing:
  // the chi-square approximation of a 4-parameter fit needs ~3x as many rows.
  int min_piece_pairs = 12;
  // The spacing, mm, at which FitTrace tests a drag's pairs: pairs closer
  // than that are averaged in consecutive groups first (pair_groups.h), so a
  // rig sampling at 500 Hz is tested as one at 100 Hz (the pairs of the
  // paper's 10 mm/s and 100 Hz are ~0.1 mm apart: left as they are).
  // 0 = the pairs as they come, whatever their spacing.
  double group_spacing_mm = 0.1;
  bool IsValid(std::string* why) const;
};

struct ChangePoint {
  int index = 0;              // first element after the change (1..n-1)
  double s_mm = 0.0;          // midway between elements index - 1 and index
  // LR at the split when it was found, and the chi-square(4) value it
  // exceeded; for an end split off, the squared standardised residual and
  // the squared normal quantile.
  double statistic = 0.0;
  double critical_value = 0.0;
};

// `s_mm` (non-decreasing positions along the path) and `values` (e.g. the
// per-pair mu) of equal length. Returns the changes in increasing order.
// Errors (INVALID_ARGUMENT): invalid options, lengths that differ, non-finite
// values, positions that decrease.
absl::StatusOr<std::vector<ChangePoint>> DetectChangePoints(std::span<const double> s_mm,
                                                            std::span<const double> values,
                                                            const ChangePointOptions& options = {});

}  // namespace surfmap
