// A drag as a line sample: what the sampling plan and the map take from a
// fit. The path of the data window on the object (a polyline, every ~1 mm)
// and the pure pieces along it, each with its extent, friction and, when it
// was long enough for its own fit, roughness. Compact (a 20 mm drag: ~17
// points and a few pieces) so that the plan journal can carry it.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>
#include "absl/status/status.h"
#include "server/estimate/fit_trace.h"
#include "server/estimate/texture.h"

namespace surfmap {

struct LinePiece {
  double start_mm = 0.0;  // along the path, in the frame of LineSample::path_s_mm
  double end_mm = 0.0;
  bool starts_at_change = false;  // a detected material change bounds it there
  bool ends_at_change = false;
  // mu, mu_std (the per-pair spread) and, only when the piece's own roughness
  // fit exists and is stationary, reflection and sigma (otherwise empty / 0).
  TextureParams texture;
  double mu_se = 0.0;            // standard error of texture.mu (serial correlation included)
  double effective_pairs = 0.0;  // independent pairs behind mu and mu_std
  // Values of one pass behind the roughness fit (its series holds both
  // passes, which feel the same texture); 0 without a fit, and where the fit
  // is below the sensor's noise floor (its shape is the noise's, not the
  // texture's).
  int roughness_rows = 0;
  bool has_roughness() const { return texture.sigma > 0.0 && !texture.reflection.empty(); }
};

struct LineSample {
  std::vector<double> path_s_mm;             // increasing
  std::vector<Eigen::Vector3d> path_points;  // mm, object frame, one per path_s_mm
  std::vector<LinePiece> pieces;             // in path order, end of one = start of the next
  // The per-pair friction series behind the pieces (FrictionFit::pair_s_mm,
  // pair_mu; positions in the frame of path_s_mm, increasing): what lets the
  // map test a piece again against the textures other drags found
  // (server/map/known_texture_split.h). Empty for fits and plans stored
  // before it was kept.
  std::vector<double> pair_s_mm;
  std::vector<double> pair_mu;

  // The path point at arc length s (linear between path points, clamped to
  // the ends). The path must not be empty.
  Eigen::Vector3d PointAt(double s_mm) const;
  // Points of [from_mm, to_mm] along the path: both ends and every path point
  // between (clamped to the path). Empty when to < from or the path is empty.
  std::vector<Eigen::Vector3d> PointsBetween(double from_mm, double to_mm) const;

  // OK, or INVALID_ARGUMENT naming the field: no path point, sizes that
  // differ, non-finite values, decreasing s, no piece, pieces out of order,
  // outside the path or with invalid textures (mu not finite, mu_std, mu_se or
  // sigma negative, |k| >= 1), a pair series whose sizes differ or whose
  // values are not finite or positions not increasing.
  absl::Status Validate() const;
};

// The line sample of a fit: its path and pieces. A piece's roughness is kept
// only when it was fitted and is stationary. A fit without pieces (stored by
// an estimator before pieces existed) gives one piece over the data window
// with the headline texture (TextureOf) and mu_se = mu_std / sqrt(n_pairs);
// without a path, the path is empty (callers place such a sample at its site).
LineSample LineSampleOf(const TraceFit& fit);

// One texture for the whole drag, for rules that compare drags as points
// (the paper's threshold rule): mu and spread weighted by the pieces'
// lengths (equally when every piece has length 0), the roughness of the
// longest piece that has its own.
TextureParams SummaryTexture(const LineSample& line);

// A line sample at one point: the form of a fit known only by its texture
// (the old SamplingPlan::RecordFit), a single piece of zero length there,
// with mu_se = mu_std / sqrt(kPointSampleEffectivePairs).
inline constexpr double kPointSampleEffectivePairs = 10.0;
LineSample PointLineSample(const Eigen::Vector3d& point, const TextureParams& texture);

}  // namespace surfmap
