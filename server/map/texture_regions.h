// Grouping the pieces of the drags into regions of like texture: the
// segmentation that keeps the map's boundaries sharp. Pieces that touch on
// the surface (their Voronoi cells meet, or they follow each other along a
// drag) are merged, most alike first, while the merged groups stay
// statistically indistinguishable:
//
//   mu:      |mu_A - mu_B| <= max(mu_resolution, z sqrt(se_A^2 + se_B^2))
//   spread:  |ln s_A - ln s_B| <= max(ln spread_resolution,
//                                     z sqrt(1 / (2 n_A) + 1 / (2 n_B)))
//
// with a group's mu the precision-weighted mean of its pieces' mu (se from
// the weights), s the pooled per-pair spread and n its effective pairs (the
// spread of n independent normal values has a log standard error of
// ~1 / sqrt(2 n)), z the two-sided normal quantile at `false_split_probability`.
//   roughness, where both have a signature, for each reflection coefficient:
//            |k_A - k_B| <= max(reflection_resolution,
//                               z f sqrt((1 - k_A^2) / n_A + (1 - k_B^2) / n_B))
//
// (f = reflection_se_factor)
//
// The spread and the roughness are the texture's signature: rubber (0.305)
// and masonite (0.36) are one drag's noise apart in mu (a masonite piece of
// 5 mm reads anywhere in 0.30-0.45: its texture wanders slowly) but ~3x
// apart in spread and far apart in shape (k2 +0.25 against -0.73; one
// piece's k is known to ~0.1). (1 - k^2) / n is the large-sample variance
// of a reflection coefficient estimated from n values (exact for an AR(1)
// coefficient; an approximation for the others, with n the values of one
// pass, since a drag's two passes feel the same texture). Pieces of one
// drag on both sides of a detected change are never merged, unless they are
// alike within the resolutions (a change that is statistically real but
// smaller than anything worth mapping).
//
// Greedy merging tests a group only against the group it joins, so a chain
// of short, noisy pieces can carry one texture into another's region (a
// 16 mm rubber drag into a masonite patch, through a piece that was mostly
// rubber and two short masonite pieces: the patch read 0.330 for 0.36). So
// after merging, each group's piece least like the rest of the group (the
// same rule, the piece against the group without it), if unlike, moves for
// good to a touching group it is alike to and more alike to than to its own
// rest, or stays where none is (a piece straddling two textures is unlike
// both); this repeats until no group has a piece to move. Groups kept apart
// only by a moved piece are then merged where they are alike as wholes.
#pragma once

#include <array>
#include <string>
#include <utility>
#include <vector>

namespace surfmap {

struct PieceStatistics {
  double mu = 0.0;
  double mu_se = 0.0;        // > 0 (callers floor it)
  double spread = 0.0;       // per-pair standard deviation, > 0 (callers floor it)
  double effective_pairs = 1.0;
  // The roughness signature: reflection coefficients k1..k_order of the
  // piece's own AR fit and, per coefficient, the series values behind it
  // (a pool's sum); order 0 = none. Coefficients past kMaxSignatureOrder are
  // not compared.
  static constexpr int kMaxSignatureOrder = 4;
  int signature_order = 0;
  std::array<double, kMaxSignatureOrder> reflection{};
  std::array<double, kMaxSignatureOrder> reflection_rows{};
};

struct RegionMergeOptions {
  // Chance that two pieces of one material are kept apart by one test. A map
  // makes a few hundred comparisons; at 1e-3 a false split is rare, and one
  // only costs a refinement at a boundary that is not there.
  double false_split_probability = 1e-3;
  // Friction differences below this are not mapped as boundaries, however
  // significant: the run-to-run repeatability of a friction coefficient is a
  // few hundredths, and the closest of the paper's materials (rubber 0.305,
  // masonite 0.36) differ by 0.055. Without it, glass pieces known to
  // +-0.0003 would split on differences of 0.001.
  double mu_resolution = 0.01;
  // Likewise for the per-pair spread: ratios below this are one texture.
  double spread_resolution = 1.25;
  // Spreads below this compare as this: a surface whose per-pair mu varies
  // by less than a hundredth (mu_resolution) is smooth at the resolution the
  // map resolves, and what its spread measures is the sensor's noise over
  // the load. Measured over the stored jobs of 15 scenes (pieces of one
  // material, 1st-99th percentile): glass 0.0017-0.0037, varying with the
  // drag; wood 0.015-0.031, rubber 0.018-0.054. Without it glass pieces next
  // to a change (0.004-0.006) became a second glass material, and crossings
  // into the two did not link (held_vase seed 2: its band pinched off, 84.5 %).
  // 0 = spreads compared however small (the plan's map, as before).
  double spread_floor = 0.01;
  // Likewise for reflection coefficients: the fitted shape of one texture
  // varies with the drag's direction and the sensor's noise by more than the
  // fit's own error says; the paper's materials differ by >= 0.3.
  double reflection_resolution = 0.3;
  // The large-sample variance above understates how far one texture's
  // estimates from short pieces scatter: measured on the simulator over six
  // jobs per scene, pieces of one material (median 7-11 mm) scatter 1.1-2.5x
  // its standard error. Its standard error is taken this many times larger.
  double reflection_se_factor = 2.0;
  // Whether the roughness signature takes part (off: the rule of mu and
  // spread alone, for comparison).
  bool compare_roughness = true;
  bool IsValid(std::string* why) const;
};

// `adjacent`: pairs of piece indices that touch; `cannot_link`: pairs known
// to differ (the pieces on both sides of a detected change). Returns the
// region of each piece, numbered 0.. in order of each region's lowest piece.
// Indices out of range are ignored (callers validate).
std::vector<int> MergeIntoRegions(const std::vector<PieceStatistics>& pieces,
                                  const std::vector<std::pair<int, int>>& adjacent,
                                  const std::vector<std::pair<int, int>>& cannot_link,
                                  const RegionMergeOptions& options = {});

// Whether two groups are alike by the rule above (exposed for tests and the
// planner).
bool TexturesAlike(const PieceStatistics& a, const PieceStatistics& b, const RegionMergeOptions& options);

// The statistics of pieces merged into one group.
PieceStatistics PoolStatistics(const std::vector<PieceStatistics>& pieces);

}  // namespace surfmap
