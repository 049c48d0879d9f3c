#include "server/estimate/drag_pieces.h"

#include <algorithm>
#include <cmath>
#include <span>

#include <Eigen/Core>
#include "absl/status/status.h"
#include "absl/strings/str_cat.h"
#include "server/estimate/pair_groups.h"
#include "server/estimate/series_dependence.h"

namespace surfmap {
namespace {

double Median(std::vector<double> v) {
  const std::size_t n = v.size();
  const auto mid = v.begin() + n / 2;
  std::nth_element(v.begin(), mid, v.end());
  double m = *mid;
  if (n % 2 == 0) m = 0.5 * (m + *std::max_element(v.begin(), mid));
  return m;
}

}  // namespace

std::string_view PieceRoughnessName(PieceRoughness state) {
  switch (state) {
    case PieceRoughness::kFitted:
      return "fitted";
    case PieceRoughness::kTooShort:
      return "too_short";
    case PieceRoughness::kFitFailed:
      return "fit_failed";
  }
  return "too_short";
}

absl::StatusOr<std::vector<DragPiece>> CutDragPieces(const FrictionFit& friction,
                                                     const std::vector<ChangePoint>& changes, int guard_pairs,
                                                     int pairs_per_group) {
  const int n = static_cast<int>(friction.pair_mu.size());
  if (n == 0 || static_cast<int>(friction.pair_s_mm.size()) != n) {
    return absl::InvalidArgumentError(absl::StrCat("drag pieces: the friction fit has ", n, " per-pair values and ",
                                                   friction.pair_s_mm.size(), " positions"));
  }
  std::vector<int> cuts = {0};
  for (std::size_t i = 0; i < changes.size(); ++i) {
    const int k = changes[i].index;
    if (k <= cuts.back() || k >= n) {
      return absl::InvalidArgumentError(absl::StrCat("drag pieces: change ", i, " at pair ", k,
                                                     " is out of order or outside 1..", n - 1));
    }
    cuts.push_back(k);
  }
  cuts.push_back(n);
  std::vector<DragPiece> pieces;
  for (std::size_t p = 0; p + 1 < cuts.size(); ++p) {
    // The transitional pairs next to a change belong to neither piece.
    const int a = cuts[p] + (p > 0 ? guard_pairs : 0);
    const int b = cuts[p + 1] - (p + 2 < cuts.size() ? guard_pairs : 0);
    if (b - a < 2) {
      return absl::InvalidArgumentError(absl::StrCat("drag pieces: changes ", p == 0 ? 0 : p - 1, " and ", p,
                                                     " leave piece ", p, " fewer than 2 pairs"));
    }
    DragPiece piece;
    piece.first_pair = a;
    piece.pair_count = b - a;
    piece.starts_at_change = p > 0;
    piece.ends_at_change = p + 2 < cuts.size();
    piece.start_mm = piece.starts_at_change ? changes[p - 1].s_mm : friction.window_start_mm;
    piece.end_mm = piece.ends_at_change ? changes[p].s_mm : friction.window_end_mm;
    const Eigen::Map<const Eigen::VectorXd> mu(friction.pair_mu.data() + a, b - a);
    piece.mu = mu.mean();
    const Eigen::VectorXd centred = mu.array() - piece.mu;
    const double variance = piece.pair_count > 1 ? centred.squaredNorm() / (piece.pair_count - 1) : 0.0;
    piece.mu_std = std::sqrt(variance);
    piece.mu_median = Median(std::vector<double>(mu.data(), mu.data() + mu.size()));
    // The error of the mean from the piece's pairs averaged in groups at the
    // texture's spacing (pair_groups.h), as the change test saw them; at 100 Hz
    // a group is one pair. An AR(2) fitted to the raw pairs of a fast rig sees
    // five near-equal pairs per texture cell and overstates their dependence
    // (measured: a 16 mm masonite piece credited ~6 independent pairs at
    // 500 Hz against ~10 at 100 Hz, and a mu_se up to 1.5x as large).
    const PairGroups groups =
        AveragePairGroups(std::span<const double>(friction.pair_s_mm).subspan(a, b - a),
                          std::span<const double>(friction.pair_mu).subspan(a, b - a), pairs_per_group);
    const Eigen::Map<const Eigen::VectorXd> grouped(groups.values.data(),
                                                    static_cast<Eigen::Index>(groups.values.size()));
    const double n_groups = static_cast<double>(grouped.size());
    const Eigen::VectorXd grouped_centred = grouped.array() - grouped.mean();
    const double grouped_variance = n_groups > 1 ? grouped_centred.squaredNorm() / (n_groups - 1) : variance;
    const SeriesDependence dependence = EstimateSeriesDependence({grouped_centred});
    const double cap = std::max(1.0, kMaxIndependentPairsPerMm * (friction.pair_s_mm[b - 1] - friction.pair_s_mm[a]));
    const double inflation = std::clamp(std::max(dependence.mean_inflation, n_groups / cap), 1.0, n_groups);
    piece.mu_se = std::sqrt(inflation * grouped_variance / n_groups);
    piece.effective_pairs = n_groups / inflation;
    pieces.push_back(std::move(piece));
  }
  return pieces;
}

}  // namespace surfmap
