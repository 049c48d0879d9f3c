#include "server/estimate/line_sample.h"

#include <algorithm>
#include <cmath>

#include "absl/strings/str_cat.h"
#include "server/estimate/pair_groups.h"

namespace surfmap {
namespace {

absl::Status ValidateTexture(const TextureParams& t, const std::string& where) {
  auto bad = [&](const std::string& what) { return absl::InvalidArgumentError(absl::StrCat(where, ": ", what)); };
  if (!std::isfinite(t.mu)) return bad(absl::StrCat("mu is ", t.mu));
  if (!std::isfinite(t.mu_std) || t.mu_std < 0) return bad(absl::StrCat("mu_std is ", t.mu_std));
  if (!std::isfinite(t.sigma) || t.sigma < 0) return bad(absl::StrCat("sigma is ", t.sigma));
  for (std::size_t j = 0; j < t.reflection.size(); ++j) {
    if (!std::isfinite(t.reflection[j]) || std::abs(t.reflection[j]) >= 1.0) {
      return bad(absl::StrCat("reflection coefficient k", j + 1, " is ", t.reflection[j],
                              " (a stationary model needs |k| < 1)"));
    }
  }
  return absl::OkStatus();
}

}  // namespace

Eigen::Vector3d LineSample::PointAt(double s) const {
  const std::size_t n = path_s_mm.size();
  if (n == 1 || s <= path_s_mm.front()) return path_points.front();
  if (s >= path_s_mm.back()) return path_points.back();
  const std::size_t i = std::upper_bound(path_s_mm.begin(), path_s_mm.end(), s) - path_s_mm.begin();
  const double a = path_s_mm[i - 1], b = path_s_mm[i];
  const double w = b > a ? (s - a) / (b - a) : 0.0;
  return (1.0 - w) * path_points[i - 1] + w * path_points[i];
}

std::vector<Eigen::Vector3d> LineSample::PointsBetween(double from, double to) const {
  std::vector<Eigen::Vector3d> out;
  if (path_s_mm.empty() || to < from) return out;
  out.push_back(PointAt(from));
  for (std::size_t i = 0; i < path_s_mm.size(); ++i) {
    if (path_s_mm[i] > from && path_s_mm[i] < to) out.push_back(path_points[i]);
  }
  if (to > from) out.push_back(PointAt(to));
  return out;
}

absl::Status LineSample::Validate() const {
  auto bad = [](const std::string& what) { return absl::InvalidArgumentError(absl::StrCat("line sample: ", what)); };
  if (path_s_mm.empty()) return bad("the path has no point");
  if (path_s_mm.size() != path_points.size()) {
    return bad(absl::StrCat(path_s_mm.size(), " path positions but ", path_points.size(), " points"));
  }
  for (std::size_t i = 0; i < path_s_mm.size(); ++i) {
    if (!std::isfinite(path_s_mm[i]) || !path_points[i].allFinite()) {
      return bad(absl::StrCat("path point ", i, " is not finite"));
    }
    if (i > 0 && path_s_mm[i] < path_s_mm[i - 1]) {
      return bad(absl::StrCat("path position ", i, " (", path_s_mm[i], " mm) is before the previous one"));
    }
  }
  if (pieces.empty()) return bad("no piece");
  if (pair_s_mm.size() != pair_mu.size()) {
    return bad(absl::StrCat(pair_s_mm.size(), " pair positions but ", pair_mu.size(), " pair values"));
  }
  for (std::size_t i = 0; i < pair_mu.size(); ++i) {
    if (!std::isfinite(pair_s_mm[i]) || !std::isfinite(pair_mu[i])) return bad(absl::StrCat("pair ", i, " is not finite"));
    if (i > 0 && pair_s_mm[i] < pair_s_mm[i - 1]) {
      return bad(absl::StrCat("pair position ", i, " (", pair_s_mm[i], " mm) is before the previous one"));
    }
  }
  const double slack = 1e-6 * (1.0 + std::abs(path_s_mm.back()));
  for (std::size_t p = 0; p < pieces.size(); ++p) {
    const LinePiece& piece = pieces[p];
    const std::string where = absl::StrCat("line sample: piece ", p);
    if (!std::isfinite(piece.start_mm) || !std::isfinite(piece.end_mm) || piece.end_mm < piece.start_mm) {
      return absl::InvalidArgumentError(absl::StrCat(where, ": extent ", piece.start_mm, "..", piece.end_mm, " mm"));
    }
    if (piece.start_mm < path_s_mm.front() - slack || piece.end_mm > path_s_mm.back() + slack) {
      return absl::InvalidArgumentError(absl::StrCat(where, ": extent ", piece.start_mm, "..", piece.end_mm,
                                                     " mm is outside the path ", path_s_mm.front(), "..",
                                                     path_s_mm.back()));
    }
    if (p > 0 && piece.start_mm < pieces[p - 1].end_mm - slack) {
      return absl::InvalidArgumentError(absl::StrCat(where, ": starts before piece ", p - 1, " ends"));
    }
    if (!std::isfinite(piece.mu_se) || piece.mu_se < 0) {
      return absl::InvalidArgumentError(absl::StrCat(where, ": mu_se is ", piece.mu_se));
    }
    if (!std::isfinite(piece.effective_pairs) || piece.effective_pairs < 0) {
      return absl::InvalidArgumentError(absl::StrCat(where, ": effective_pairs is ", piece.effective_pairs));
    }
    if (piece.roughness_rows < 0 || (piece.roughness_rows > 0 && !piece.has_roughness())) {
      return absl::InvalidArgumentError(absl::StrCat(where, ": roughness_rows is ", piece.roughness_rows,
                                                     piece.roughness_rows > 0 ? " without a roughness fit" : ""));
    }
    if (absl::Status s = ValidateTexture(piece.texture, where); !s.ok()) return s;
  }
  return absl::OkStatus();
}

LineSample LineSampleOf(const TraceFit& fit) {
  LineSample line;
  line.path_s_mm = fit.path.s_mm;
  line.path_points = fit.path.points;
  if (fit.pieces.empty()) {
    LinePiece piece;
    piece.start_mm = fit.friction.window_start_mm;
    piece.end_mm = fit.friction.window_end_mm;
    piece.texture = TextureOf(fit);
    const int n = std::max(1, fit.friction.n_pairs);
    piece.mu_se = fit.friction.mu_std / std::sqrt(static_cast<double>(n));
    piece.effective_pairs = n;
    line.pieces.push_back(std::move(piece));
    return line;
  }
  // The series the map tests pieces on again, at the spacing the drag's own
  // test saw (pair_groups.h; the pairs themselves at 100 Hz).
  PairGroups groups = AveragePairGroups(fit.friction.pair_s_mm, fit.friction.pair_mu, fit.pairs_per_group);
  line.pair_s_mm = std::move(groups.s_mm);
  line.pair_mu = std::move(groups.values);
  for (const DragPiece& p : fit.pieces) {
    LinePiece piece;
    piece.start_mm = p.start_mm;
    piece.end_mm = p.end_mm;
    piece.starts_at_change = p.starts_at_change;
    piece.ends_at_change = p.ends_at_change;
    piece.texture.mu = p.mu;
    piece.texture.mu_std = p.mu_std;
    if (p.roughness_state == PieceRoughness::kFitted && p.roughness.stationary) {
      piece.texture.reflection = p.roughness.reflection;
      piece.texture.sigma = p.roughness.sigma;
      if (!p.roughness.below_noise_floor && piece.has_roughness()) piece.roughness_rows = std::max(1, p.roughness.n / 2);
    }
    piece.mu_se = p.mu_se;
    piece.effective_pairs = p.effective_pairs;
    line.pieces.push_back(std::move(piece));
  }
  return line;
}

TextureParams SummaryTexture(const LineSample& line) {
  TextureParams out;
  double total = 0.0;
  for (const LinePiece& p : line.pieces) total += p.end_mm - p.start_mm;
  const bool equal = !(total > 0.0);
  double weights = 0.0, mu = 0.0, var = 0.0;
  int roughest = -1;
  for (std::size_t i = 0; i < line.pieces.size(); ++i) {
    const LinePiece& p = line.pieces[i];
    const double w = equal ? 1.0 : p.end_mm - p.start_mm;
    weights += w;
    mu += w * p.texture.mu;
    var += w * p.texture.mu_std * p.texture.mu_std;
    if (p.has_roughness() &&
        (roughest < 0 || p.end_mm - p.start_mm > line.pieces[roughest].end_mm - line.pieces[roughest].start_mm)) {
      roughest = static_cast<int>(i);
    }
  }
  if (weights > 0.0) {
    out.mu = mu / weights;
    out.mu_std = std::sqrt(var / weights);
  }
  if (roughest >= 0) {
    out.reflection = line.pieces[roughest].texture.reflection;
    out.sigma = line.pieces[roughest].texture.sigma;
  }
  return out;
}

LineSample PointLineSample(const Eigen::Vector3d& point, const TextureParams& texture) {
  LineSample line;
  line.path_s_mm = {0.0};
  line.path_points = {point};
  LinePiece piece;
  piece.texture = texture;
  // Known only by its spread: assume the fewest independent pairs a 16 mm
  // window over a correlated texture holds (rubber's gives ~11; glass ~160),
  // so the error is not understated.
  piece.effective_pairs = kPointSampleEffectivePairs;
  piece.mu_se = texture.mu_std / std::sqrt(kPointSampleEffectivePairs);
  line.pieces.push_back(std::move(piece));
  return line;
}

}  // namespace surfmap
