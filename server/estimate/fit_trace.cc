#include "server/estimate/fit_trace.h"

#include <algorithm>
#include <cmath>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "server/estimate/ar_bias_correction.h"
#include "server/estimate/drag_passes.h"
#include "server/estimate/force_variation.h"
#include "server/estimate/pair_groups.h"
#include "server/estimate/series_noise.h"

namespace surfmap {
namespace {

// Forward positions at s = window start, start + step, ..., window end.
DragPathSamples SamplePath(std::span<const DragSample> forward, const PathPairing& pairing,
                           const FrictionFit& friction, double step_mm) {
  DragPathSamples path;
  const double start = friction.window_start_mm, end = friction.window_end_mm;
  const int n = static_cast<int>(forward.size());
  const auto key = [&](int i) { return pairing.forward_s[i]; };
  MonotoneBracket bracket(n);
  const int steps = std::max(1, static_cast<int>(std::ceil((end - start) / step_mm - 1e-9)));
  for (int k = 0; k <= steps; ++k) {
    const double s = k == steps ? end : start + k * step_mm;
    int i;
    double w;
    bracket.Locate(s, key, &i, &w);
    const int j = std::min(i + 1, n - 1);
    path.s_mm.push_back(s);
    path.points.push_back((1.0 - w) * forward[i].position + w * forward[j].position);
  }
  return path;
}

// The noise floor against the propagated noise: a texture of at most twice
// the noise the series carries is not resolved (ArFitOptions::
// noise_floor_ratio). Version 7 drew the line at 1.5 times the white model,
// which is twice that noise, so the line stays where it was: with 1.5 here,
// 2-7 % of glass drags (sigma 0.003-0.005 N) and a fifth of steel's (0.006)
// got a roughness fitted to what is mostly noise, and a map split its glass
// into two materials by it (held_torus seed 3: rubber 91 -> 83 %).
constexpr double kPropagatedNoiseFloorRatio = 3.0;

// `noise`: the noise propagated to the stretch's series, or empty when the
// propagation failed (then the white model).
ArFitOptions RoughnessOptions(const FitOptions& options, double noise_std, double mu,
                              std::vector<double> noise) {
  ArFitOptions ar;
  ar.order = options.ar_order;
  ar.method = options.ar_method;
  ar.step_mm = options.step_mm;
  if (!options.noise_aware) return ar;
  if (!noise.empty()) {
    ar.noise_autocovariance = std::move(noise);
    ar.noise_floor_ratio = kPropagatedNoiseFloorRatio;
  } else {
    ar.noise_variance = noise_std * noise_std * (1.0 + mu * mu);
  }
  return ar;
}

// The noise on each stretch's series (series_noise.h), or empty vectors when
// there is none to correct for, it is not to be propagated
// (noise_replicates 0) or it could not be.
std::vector<std::vector<double>> StretchNoise(std::span<const DragSample> forward,
                                              std::span<const DragSample> reverse,
                                              const PathPairing& pairing, const DataWindow& window,
                                              const FitOptions& options, const TraceFit& fit,
                                              const std::vector<SeriesStretch>& stretches) {
  std::vector<std::vector<double>> none(stretches.size());
  if (!options.noise_aware || !(fit.noise_std > 0.0) || stretches.empty() || options.noise_replicates == 0) {
    return none;
  }
  SeriesNoiseOptions noise;
  noise.noise_std = fit.noise_std;
  noise.step_mm = options.step_mm;
  noise.max_lag = options.ar_order;
  noise.replicates = options.noise_replicates;
  noise.series = options.series;
  noise.seed = BiasSeedFromData(fit.friction.mu, fit.friction.window_start_mm);
  absl::StatusOr<std::vector<std::vector<double>>> propagated =
      PropagateSeriesNoise(forward, reverse, pairing, window, options.friction, fit.friction, stretches, noise);
  return propagated.ok() ? *std::move(propagated) : none;
}

// The stretch a piece's roughness is fitted over: the piece less the guard at
// each change.
SeriesStretch PieceStretch(const DragPiece& piece, const FitOptions& options) {
  return {piece.start_mm + (piece.starts_at_change ? options.change_guard_mm : 0.0),
          piece.end_mm - (piece.ends_at_change ? options.change_guard_mm : 0.0), piece.mu};
}

// The roughness of each piece of a drag that crossed material changes, fitted
// over the piece alone (less the guard next to each change).
void FitPieceRoughness(std::span<const DragSample> forward, std::span<const DragSample> reverse,
                       const PathPairing& pairing, const DataWindow& window, const FitOptions& options,
                       TraceFit& fit) {
  std::vector<SeriesStretch> stretches;
  for (const DragPiece& piece : fit.pieces) {
    const SeriesStretch stretch = PieceStretch(piece, options);
    if (stretch.end_mm - stretch.start_mm >= options.min_roughness_piece_mm) stretches.push_back(stretch);
  }
  std::vector<std::vector<double>> noise = StretchNoise(forward, reverse, pairing, window, options, fit, stretches);
  std::size_t next_noise = 0;
  for (DragPiece& piece : fit.pieces) {
    const auto [start, end, mu] = PieceStretch(piece, options);
    if (end - start < options.min_roughness_piece_mm) {
      piece.roughness_state = PieceRoughness::kTooShort;
      piece.roughness_note = absl::StrCat("piece of ", end - start, " mm is shorter than the ",
                                          options.min_roughness_piece_mm, " mm a roughness fit needs");
      continue;
    }
    absl::StatusOr<std::vector<Eigen::VectorXd>> series =
        ForceVariationSeries(forward, reverse, pairing, fit.friction, start, end, piece.mu, options.step_mm,
                             options.series);
    ArFitOptions ar = RoughnessOptions(options, fit.noise_std, mu, std::move(noise[next_noise++]));
    ar.bias_replicates = options.piece_bias_replicates;
    ar.segments_detrended = true;  // ForceVariationSeries removed a line from each segment
    // A seed from the piece's own data (deterministic for a trace), so the
    // pieces pooled into a map do not share one Monte-Carlo error.
    ar.bias_seed = BiasSeedFromData(piece.mu, start);
    absl::StatusOr<ArFit> roughness = series.ok() ? FitAutoregressive(*series, ar)
                                                  : absl::StatusOr<ArFit>(series.status());
    if (!roughness.ok()) {
      piece.roughness_state = PieceRoughness::kFitFailed;
      piece.roughness_note = std::string(roughness.status().message());
      continue;
    }
    piece.roughness_state = PieceRoughness::kFitted;
    piece.roughness = *std::move(roughness);
  }
  // The drag's roughness: the longest fitted piece.
  fit.roughness_piece = -1;
  for (int p = 0; p < static_cast<int>(fit.pieces.size()); ++p) {
    if (fit.pieces[p].roughness_state != PieceRoughness::kFitted) continue;
    if (fit.roughness_piece < 0 || fit.pieces[p].length_mm() > fit.pieces[fit.roughness_piece].length_mm()) {
      fit.roughness_piece = p;
    }
  }
  fit.roughness = fit.roughness_piece >= 0 ? fit.pieces[fit.roughness_piece].roughness : ArFit{};
}

}  // namespace

bool FitOptions::IsValid(std::string* why) const {
  auto fail = [&](std::string message) {
    if (why) *why = std::move(message);
    return false;
  };
  if (!(step_mm > 0.0)) return fail("step_mm must be > 0");
  if (ar_order < 1) return fail("ar_order must be >= 1");
  if (min_pass_samples < 2) return fail("min_pass_samples must be >= 2");
  std::string inner;
  WindowOptions window{min_speed_fraction, WindowOptions{}.smoothing_s, window_trim_fraction};
  if (!window.IsValid(&inner)) return fail(inner);
  if (!pairing.IsValid(&inner)) return fail(absl::StrCat("pairing: ", inner));
  if (!friction.IsValid(&inner)) return fail(absl::StrCat("friction: ", inner));
  if (!changes.IsValid(&inner)) return fail(absl::StrCat("changes: ", inner));
  if (!(std::isfinite(min_roughness_piece_mm) && min_roughness_piece_mm > 0.0)) {
    return fail("min_roughness_piece_mm must be > 0");
  }
  if (!(std::isfinite(change_guard_mm) && change_guard_mm >= 0.0)) return fail("change_guard_mm must be >= 0");
  if (!(std::isfinite(path_step_mm) && path_step_mm > 0.0)) return fail("path_step_mm must be > 0");
  if (noise_replicates < 0 || noise_replicates > 64) return fail("noise_replicates must be in 0..64");
  if (!series.IsValid(&inner)) return fail(inner);
  if (piece_bias_replicates < 0 || piece_bias_replicates > 10000) {
    return fail("piece_bias_replicates must be in 0..10000");
  }
  return true;
}

absl::StatusOr<TraceFit> FitTrace(const DragTrace& trace, const FitOptions& options) {
  std::string why;
  if (!options.IsValid(&why)) return absl::InvalidArgumentError(absl::StrCat("FitOptions: ", why));
  absl::StatusOr<DragPasses> passes = SplitDragPasses(trace);
  if (!passes.ok()) return passes.status();
  const auto& [forward, pause, reverse, pause_offset, reverse_offset] = *passes;
  if (static_cast<int>(forward.size()) < options.min_pass_samples ||
      static_cast<int>(reverse.size()) < options.min_pass_samples) {
    return absl::InvalidArgumentError(absl::StrCat(
        "too few samples: forward pass ", forward.size(), ", reverse pass ", reverse.size(),
        "; a fit needs at least ", options.min_pass_samples, " in each"));
  }

  absl::StatusOr<PathPairing> pairing = PairPasses(forward, reverse, options.pairing);
  if (!pairing.ok()) return pairing.status();
  WindowOptions window_options;
  window_options.min_speed_fraction = options.min_speed_fraction;
  window_options.trim_fraction = options.window_trim_fraction;
  absl::StatusOr<DataWindow> window = ChooseDataWindow(forward, reverse, *pairing, window_options);
  if (!window.ok()) return window.status();

  TraceFit fit;
  absl::StatusOr<FrictionFit> friction =
      FitFriction(forward, reverse, *pairing, *window, options.friction);
  if (!friction.ok()) return friction.status();
  fit.friction = *std::move(friction);
  fit.path_length_mm = pairing->path_length_mm;
  fit.max_retrace_offset_mm = pairing->max_offset_mm;
  fit.noise_std = PauseNoiseStd(pause);

  // Both grids over the window are sized by its length: checked before either
  // is allocated (a trace with positions scaled by 1e6 asked for gigabytes).
  const double window_mm = fit.friction.window_end_mm - fit.friction.window_start_mm;
  const struct {
    double step_mm;
    const char* name;
  } grids[] = {{options.step_mm, "roughness grid"}, {options.path_step_mm, "path grid"}};
  for (const auto& grid : grids) {
    const double points = std::floor(window_mm / grid.step_mm + 1e-9) + 1.0;
    if (points > kMaxRoughnessGridPoints) {
      return absl::InvalidArgumentError(absl::StrFormat(
          "data window %.6g..%.6g mm holds %.4g points of the %.3g mm %s; the limit is %d",
          fit.friction.window_start_mm, fit.friction.window_end_mm, points, grid.step_mm, grid.name,
          kMaxRoughnessGridPoints));
    }
  }
  fit.path = SamplePath(forward, *pairing, fit.friction, options.path_step_mm);

  // Tested at the texture grid's spacing whatever the rig's sample rate.
  fit.pairs_per_group = PairsPerGroup(fit.friction.pair_s_mm, options.changes.group_spacing_mm);
  const PairGroups groups = AveragePairGroups(fit.friction.pair_s_mm, fit.friction.pair_mu, fit.pairs_per_group);
  absl::StatusOr<std::vector<ChangePoint>> changes = DetectChangePoints(groups.s_mm, groups.values, options.changes);
  if (!changes.ok()) return changes.status();
  fit.changes = ChangesOfPairs(*changes, fit.friction.pair_s_mm, fit.pairs_per_group);
  absl::StatusOr<std::vector<DragPiece>> pieces =
      CutDragPieces(fit.friction, fit.changes, fit.pairs_per_group * kChangeGuardPairs, fit.pairs_per_group);
  if (!pieces.ok()) return pieces.status();
  fit.pieces = *std::move(pieces);
  if (fit.pieces.size() > 1) {
    FitPieceRoughness(forward, reverse, *pairing, *window, options, fit);
    return fit;
  }

  // One piece: the whole window, fitted as it always was (an error if it fails).
  absl::StatusOr<std::vector<Eigen::VectorXd>> series =
      ForceVariationSeries(forward, reverse, *pairing, fit.friction, options.step_mm, options.series);
  if (!series.ok()) return series.status();
  const std::vector<SeriesStretch> whole{
      {fit.friction.window_start_mm, fit.friction.window_end_mm, fit.friction.mu}};
  std::vector<std::vector<double>> noise = StretchNoise(forward, reverse, *pairing, *window, options, fit, whole);
  absl::StatusOr<ArFit> roughness =
      FitAutoregressive(*series, RoughnessOptions(options, fit.noise_std, fit.friction.mu, std::move(noise[0])));
  if (!roughness.ok()) {
    return absl::Status(roughness.status().code(),
                        absl::StrCat("roughness fit: ", roughness.status().message()));
  }
  fit.roughness = *std::move(roughness);
  fit.roughness_piece = 0;
  DragPiece& piece = fit.pieces.front();
  if (piece.length_mm() >= options.min_roughness_piece_mm) {
    piece.roughness_state = PieceRoughness::kFitted;
    piece.roughness = fit.roughness;
  } else {
    piece.roughness_state = PieceRoughness::kTooShort;
    piece.roughness_note = absl::StrCat("piece of ", piece.length_mm(), " mm is shorter than the ",
                                        options.min_roughness_piece_mm, " mm a roughness fit needs");
  }
  return fit;
}

TextureParams TextureOf(const TraceFit& fit) {
  TextureParams t;
  t.mu = fit.friction.mu;
  t.mu_std = fit.friction.mu_std;
  if (fit.roughness.stationary) {
    t.reflection = fit.roughness.reflection;
    t.sigma = fit.roughness.sigma;
  }
  return t;
}

}  // namespace surfmap
