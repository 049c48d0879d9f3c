// Test support (header-only, not part of the library): map pieces along
// straight drags on a flat plate, for RegionMap and the planner's tests.
#pragma once

#include <cmath>
#include <cstdint>
#include <numeric>
#include <vector>

#include <Eigen/Core>
#include "server/estimate/series_for_test.h"
#include "server/map/region_map.h"
#include "server/map/testing/flat_grid_levels.h"

namespace surfmap::testing {

// A 100 x 50 mm plate, x in [-50, 50], y in [-25, 25], z = 0, 2.5 mm cells:
// finer than a drag, coarse enough that a test builds in milliseconds.
inline SurfaceLevel Plate() { return MakeFlatGrid(40, 20, 2.5, -50.0, -25.0); }

// One pure piece of drag `drag` from a to b (mm), lying from_mm along its
// drag, with friction mu known to `mu_se`; with roughness (AR(2) reflection
// coefficients 0.6, -0.25 and sigma 0.11, rubber-like) when `rough`.
inline MapPiece StraightPiece(int drag, const Eigen::Vector3d& a, const Eigen::Vector3d& b, double mu,
                              double from_mm = 0.0, bool rough = false, double mu_se = 0.002) {
  MapPiece p;
  p.drag = drag;
  p.points = {a, b};
  p.piece.start_mm = from_mm;
  p.piece.end_mm = from_mm + (b - a).norm();
  p.piece.texture.mu = mu;
  p.piece.texture.mu_std = 0.01;
  if (rough) {
    p.piece.texture.reflection = {0.6, -0.25};
    p.piece.texture.sigma = 0.11;
  }
  p.piece.mu_se = mu_se;
  p.piece.effective_pairs = 10.0;
  return p;
}

// A piece from a to b whose statistics and pair series are those of
// `stretches` (0.1 mm apart), as one piece: no change was detected in it.
inline MapPiece PieceWithSeries(int drag, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                         const std::vector<Stretch>& stretches, std::uint64_t seed) {
  const std::vector<double> x = Series(stretches, seed);
  const double mean = std::accumulate(x.begin(), x.end(), 0.0) / x.size();
  double var = 0.0;
  for (double v : x) var += (v - mean) * (v - mean);
  var /= x.size() - 1;
  MapPiece p = StraightPiece(drag, a, b, mean);
  p.piece.end_mm = 0.1 * (x.size() - 1);
  p.piece.texture.mu_std = std::sqrt(var);
  p.piece.effective_pairs = x.size() / 16.0;  // one independent pair per 1.6 mm
  p.piece.mu_se = std::sqrt(var / p.piece.effective_pairs);
  p.point_s_mm = {0.0, p.piece.end_mm};
  for (std::size_t i = 0; i < x.size(); ++i) p.pair_s_mm.push_back(0.1 * i);
  p.pair_mu = x;
  return p;
}

// A masonite-like piece (mu 0.36; reflection coefficients 0.93, -0.73, sigma
// 0.16) or a wood-like one (0.42; 0.83, -0.45, sigma 0.06): alike frictions,
// different roughness (the scan_stone_m scene's strip on its body).
inline MapPiece MasonitePiece(int drag, const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  MapPiece p = StraightPiece(drag, a, b, 0.36, 0.0, true);
  p.piece.texture.reflection = {0.93, -0.73};
  p.piece.texture.sigma = 0.16;
  return p;
}
inline MapPiece WoodPiece(int drag, const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  MapPiece p = StraightPiece(drag, a, b, 0.42, 0.0, true);
  p.piece.texture.reflection = {0.83, -0.45};
  p.piece.texture.sigma = 0.06;
  return p;
}

// The map of `pieces` on `level` with `options`; an error where it cannot
// be built.
inline absl::StatusOr<RegionMap> MapOfPieces(const SurfaceLevel& level, const std::vector<MapPiece>& pieces,
                                             const RegionMapOptions& options = {}) {
  absl::StatusOr<RegionMap> map = RegionMap::Create(level, options);
  if (!map.ok()) return map.status();
  if (absl::Status s = map->SetPieces(pieces); !s.ok()) return s;
  return map;
}

// The default texture metric restricted to `property`.
inline TextureDistanceOptions Metric(TextureProperty property) {
  TextureDistanceOptions metric;
  metric.property = property;
  return metric;
}

// A drag from a to b that crosses from mu_before to mu_after at `at` (a
// point of the segment): two pieces bounded by the detected change.
inline std::vector<MapPiece> CrossingDrag(int drag, const Eigen::Vector3d& a, const Eigen::Vector3d& at,
                                          const Eigen::Vector3d& b, double mu_before, double mu_after) {
  MapPiece first = StraightPiece(drag, a, at, mu_before);
  first.piece.ends_at_change = true;
  MapPiece second = StraightPiece(drag, at, b, mu_after, first.piece.end_mm);
  second.piece.starts_at_change = true;
  return {first, second};
}

}  // namespace surfmap::testing
