// Testing a drag's piece again against textures that are already known.
//
// The change test of one drag (change_points.h) must estimate both sides'
// AR(2) models from the drag itself, and between rubber and masonite it is
// at its information limit: a 12 mm drag split at its middle shows the
// change in about 2 of 3 drags (docs/method.md). A map knows more than one
// drag: the materials its other drags found, each with hundreds of pairs.
// With the models known, only the split's position is free, and a stretch
// of n rubber pairs under masonite's model is evidence in itself.
//
// A texture here is an AR(2) model of the per-pair friction series about the
// material's mu:
//
//   x_i - m = a1 (x_(i-1) - m) + a2 (x_(i-2) - m) + e_i,   e_i ~ N(0, v)
//
// For a series x_0..x_(n-1) (one piece) and every split k leaving enough
// pairs on each side, the log-likelihood ratio
//
//   LLR(k, A, B) = sum_left log p_A(x_i | past) + sum_right log p_B(x_i | past)
//                  - max_M sum_(both) log p_M(x_i | past)
//
// over textures A != B, with "left" the rows 2..k-2 and "right" the rows
// k+3..n-1 (the transitional pairs k-1 and k, kChangeGuardPairs, and the
// right side's first two rows, whose lags reach across the change, take no
// part; the single-texture alternative is scored on the same rows). The
// split is kept when the largest LLR exceeds log(K / alpha), K the number of
// (k, A, B) tried and alpha the false-alarm probability: if the piece is one
// of the textures and the models are right, each likelihood ratio against
// its own texture has expectation 1, so by Markov's inequality and the union
// bound the chance of any false split is at most alpha. (The models are
// estimated and the series is not exactly AR(2); the measured rates are in
// known_texture_split_test.) Both sides are searched again (binary
// segmentation).
//
// Where no single split is kept, a band is tested as the drag's own test
// does (change_points.h): texture B on pairs [k1, k2), texture A on the rest,
// each of the three parts at least the shortest side, the same LLR against
// the best single texture on the same rows, kept above log(K / alpha) with
// K every (k1, k2, A, B) tried. A drag across a strip holds both materials
// on each side of any single split, so the single split's alternative must
// explain a side that is half the other material: 5.5 mm of rubber inside
// masonite was found in 1 of 200 synthetic drags by single splits, in 169
// with the band test (the drag's own test: 136).
#pragma once

#include <span>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "server/estimate/change_points.h"

namespace surfmap {

struct SeriesTexture {
  double mean = 0.0;
  double a1 = 0.0;
  double a2 = 0.0;
  double innovation_variance = 0.0;  // > 0
};

// The AR(2) texture of several stretches of one material's series, by least
// squares about their common mean (each stretch's rows use lags within it).
// Errors (INVALID_ARGUMENT): fewer than `min_rows` rows in all (stretches of
// fewer than 3 values give none), a non-finite value, or a singular fit.
absl::StatusOr<SeriesTexture> FitSeriesTexture(const std::vector<std::span<const double>>& stretches,
                                               int min_rows = 100);

// The conditional log-likelihood of a series under a texture: the sum of
// log p(x_i | x_(i-1), x_(i-2)) over its rows i = 2..n-1 (0 for fewer than
// three values). The texture's innovation variance must be > 0.
double SeriesLogLikelihood(std::span<const double> x, const SeriesTexture& texture);

struct KnownTextureSplitOptions {
  // Bound on the family-wise chance of a false split per piece tested (see
  // above). The bound is loose: measured on 16 mm series of the paper's four
  // textures with fitted models, 0 false splits in 8,000 at 0.05 and 1 at
  // 0.2 (KnownTextureSplitTest.RatesAtTheDefault), while 3 mm of rubber
  // before masonite is found 70 % of the time at 0.05 against 32 % at 1e-3.
  // A false split only cuts a piece into two parts that the map finds alike.
  double false_alarm_probability = 0.05;
  // Shortest side, as the change test's (ChangePointOptions).
  double min_piece_mm = 1.5;
  int min_piece_pairs = 12;
  // Where no single split is kept, test a band of one texture inside
  // another (a drag across a strip; above). false = single splits only.
  bool test_bands = true;
  bool IsValid(std::string* why) const;
};

// The changes found in `mu` (positions `s_mm`, increasing, same size) between
// `textures` (at least two; fewer gives none), in order, as the change
// test's ChangePoint: index and s_mm, `statistic` the largest LLR and
// `critical_value` log(K / alpha) it exceeded. Errors
// (INVALID_ARGUMENT): sizes that differ, invalid options or a texture with
// a non-positive innovation variance.
absl::StatusOr<std::vector<ChangePoint>> FindKnownTextureChanges(std::span<const double> mu,
                                                                        std::span<const double> s_mm,
                                                                        const std::vector<SeriesTexture>& textures,
                                                                        const KnownTextureSplitOptions& options = {});

}  // namespace surfmap
