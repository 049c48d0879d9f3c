#include "server/map/piece_resplit.h"

#include <algorithm>
#include <span>

#include "server/estimate/drag_pieces.h"

namespace surfmap {
namespace {

// The points of `piece` between from and to (mm along its drag's path):
// both ends, interpolated, and the piece's points between them.
std::vector<Eigen::Vector3d> PointsBetween(const MapPiece& piece, double from, double to,
                                           std::vector<double>* positions) {
  const std::vector<double>& s = piece.point_s_mm;
  auto at = [&](double x) -> Eigen::Vector3d {
    if (x <= s.front()) return piece.points.front();
    if (x >= s.back()) return piece.points.back();
    const std::size_t i = std::upper_bound(s.begin(), s.end(), x) - s.begin();
    const double w = s[i] > s[i - 1] ? (x - s[i - 1]) / (s[i] - s[i - 1]) : 0.0;
    return (1.0 - w) * piece.points[i - 1] + w * piece.points[i];
  };
  std::vector<Eigen::Vector3d> out = {at(from)};
  positions->assign({from});
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (s[i] > from && s[i] < to) out.push_back(piece.points[i]), positions->push_back(s[i]);
  }
  if (to > from) out.push_back(at(to)), positions->push_back(to);
  return out;
}

std::vector<MapPiece> Split(const MapPiece& piece, const std::vector<KnownTextureChange>& changes) {
  FrictionFit friction;
  friction.pair_s_mm = piece.pair_s_mm;
  friction.pair_mu = piece.pair_mu;
  friction.window_start_mm = piece.piece.start_mm;
  friction.window_end_mm = piece.piece.end_mm;
  std::vector<ChangePoint> cuts;
  for (const KnownTextureChange& c : changes) {
    ChangePoint cut;
    cut.index = c.index;
    cut.s_mm = c.s_mm;
    cut.statistic = c.log_likelihood_ratio;
    cut.critical_value = c.critical_value;
    cuts.push_back(cut);
  }
  absl::StatusOr<std::vector<DragPiece>> cut = CutDragPieces(friction, cuts);
  if (!cut.ok()) return {};  // a change too close to another: keep the piece whole
  std::vector<MapPiece> out;
  for (std::size_t k = 0; k < cut->size(); ++k) {
    const DragPiece& d = (*cut)[k];
    MapPiece sub;
    sub.drag = piece.drag;
    sub.piece.start_mm = d.start_mm;
    sub.piece.end_mm = d.end_mm;
    sub.piece.starts_at_change = k == 0 ? piece.piece.starts_at_change : true;
    sub.piece.ends_at_change = k + 1 == cut->size() ? piece.piece.ends_at_change : true;
    sub.piece.texture.mu = d.mu;
    sub.piece.texture.mu_std = d.mu_std;
    sub.piece.mu_se = d.mu_se;
    sub.piece.effective_pairs = d.effective_pairs;
    sub.points = PointsBetween(piece, d.start_mm, d.end_mm, &sub.point_s_mm);
    sub.pair_s_mm.assign(piece.pair_s_mm.begin() + d.first_pair, piece.pair_s_mm.begin() + d.first_pair + d.pair_count);
    sub.pair_mu.assign(piece.pair_mu.begin() + d.first_pair, piece.pair_mu.begin() + d.first_pair + d.pair_count);
    out.push_back(std::move(sub));
  }
  return out;
}

}  // namespace

std::vector<SeriesTexture> MaterialTextures(const std::vector<MapPiece>& pieces,
                                            const std::vector<int>& piece_material, int min_rows) {
  int materials = 0;
  for (int m : piece_material) materials = std::max(materials, m + 1);
  std::vector<std::vector<std::span<const double>>> stretches(materials);
  for (std::size_t i = 0; i < pieces.size() && i < piece_material.size(); ++i) {
    if (piece_material[i] < 0 || pieces[i].pair_mu.size() < 3) continue;
    stretches[piece_material[i]].emplace_back(pieces[i].pair_mu);
  }
  std::vector<SeriesTexture> out;
  for (const auto& s : stretches) {
    if (absl::StatusOr<SeriesTexture> t = FitSeriesTexture(s, min_rows); t.ok()) out.push_back(*t);
  }
  return out;
}

std::vector<std::vector<MapPiece>> SplitPiecesAgainst(const std::vector<MapPiece>& pieces,
                                                      const std::vector<SeriesTexture>& textures,
                                                      const KnownTextureSplitOptions& options) {
  std::vector<std::vector<MapPiece>> out(pieces.size());
  if (textures.size() < 2) return out;
  for (std::size_t i = 0; i < pieces.size(); ++i) {
    const MapPiece& p = pieces[i];
    if (p.pair_mu.empty() || p.point_s_mm.empty()) continue;
    absl::StatusOr<std::vector<KnownTextureChange>> changes =
        FindKnownTextureChanges(p.pair_mu, p.pair_s_mm, textures, options);
    if (!changes.ok() || changes->empty()) continue;
    out[i] = Split(p, *changes);
  }
  return out;
}

}  // namespace surfmap
