// A drag's per-pair friction series at a fixed spacing along the path,
// whatever the rig's sample rate.
//
// The tests that read a drag's per-pair series (change_points.h, and the
// map's known_texture_split.h) model it as an AR(2) process whose
// innovations are white. At the paper's 10 mm/s and 100 Hz the pairs lie
// ~0.1 mm apart, the grid of the surface texture, and that holds. A rig that
// samples at 500 Hz puts five pairs in each texture cell: within a cell the
// values are one texture value plus the sensor's noise, across cells they
// step, and an AR(2) fit leaves correlated innovations that the
// likelihood-ratio test reads as changes (measured: 2 false changes in 30
// one-material drags at 100 Hz, 69 at 500 Hz, 179 at 1 kHz). So the tests
// see the pairs averaged in consecutive groups of k, k the series' spacing
// over the median pair spacing rounded (1 at 100 Hz: the series as it is).
#pragma once

#include <span>
#include <vector>

#include "server/estimate/change_points.h"

namespace surfmap {

// Pairs per group: round(spacing_mm / median spacing of s_mm), at least 1;
// 1 when s_mm has fewer than 2 values or no spacing > 0 (spacing_mm <= 0:
// always 1).
int PairsPerGroup(std::span<const double> s_mm, double spacing_mm);

struct PairGroups {
  std::vector<double> s_mm;    // each group's mean position
  std::vector<double> values;  // each group's mean value
};

// Group g holds pairs g k .. g k + k - 1; the last group also holds the
// pairs left over (fewer than k), so no group is short. k < 1 is taken as 1.
PairGroups AveragePairGroups(std::span<const double> s_mm, std::span<const double> values, int k);

// Changes found in the groups of k, as changes of the pairs: a change
// before group g is before pair g k, at the midpoint of pairs g k - 1 and
// g k. `pair_s_mm` is the pairs' positions.
std::vector<ChangePoint> ChangesOfPairs(const std::vector<ChangePoint>& group_changes, std::span<const double> pair_s_mm,
                                        int k);

}  // namespace surfmap
