#include "server/map/piece_resplit.h"

#include <algorithm>
#include <span>

#include "absl/strings/str_cat.h"
#include "server/estimate/drag_pieces.h"

namespace surfmap {
namespace {

absl::StatusOr<std::vector<MapPiece>> Split(const MapPiece& piece, const std::vector<ChangePoint>& cuts) {
  FrictionFit friction;
  friction.pair_s_mm = piece.pair_s_mm;
  friction.pair_mu = piece.pair_mu;
  friction.window_start_mm = piece.piece.start_mm;
  friction.window_end_mm = piece.piece.end_mm;
  // The search keeps at least min_piece_pairs on each side of a change, so
  // every part has its pairs; an error here is a broken invariant.
  absl::StatusOr<std::vector<DragPiece>> cut = CutDragPieces(friction, cuts);
  if (!cut.ok()) return cut.status();
  LineSample path;  // the piece's own points as a path, to cut along
  path.path_s_mm = piece.point_s_mm;
  path.path_points = piece.points;
  std::vector<MapPiece> out;
  for (std::size_t k = 0; k < cut->size(); ++k) {
    const DragPiece& d = (*cut)[k];
    MapPiece sub;
    sub.drag = piece.drag;
    sub.line_piece = piece.line_piece;
    sub.split_by_map = true;
    sub.piece.start_mm = d.start_mm;
    sub.piece.end_mm = d.end_mm;
    sub.piece.starts_at_change = k == 0 ? piece.piece.starts_at_change : true;
    sub.piece.ends_at_change = k + 1 == cut->size() ? piece.piece.ends_at_change : true;
    sub.piece.texture.mu = d.mu;
    sub.piece.texture.mu_std = d.mu_std;
    sub.piece.mu_se = d.mu_se;
    sub.piece.effective_pairs = d.effective_pairs;
    PlaceAlong(path, d.start_mm, d.end_mm, &sub);
    sub.pair_s_mm.assign(piece.pair_s_mm.begin() + d.first_pair, piece.pair_s_mm.begin() + d.first_pair + d.pair_count);
    sub.pair_mu.assign(piece.pair_mu.begin() + d.first_pair, piece.pair_mu.begin() + d.first_pair + d.pair_count);
    out.push_back(std::move(sub));
  }
  return out;
}

absl::Status Named(const absl::Status& status, std::size_t piece) {
  return absl::Status(status.code(), absl::StrCat("map piece ", piece, ": ", status.message()));
}

}  // namespace

std::vector<std::optional<SeriesTexture>> MaterialTextures(const std::vector<MapPiece>& pieces,
                                                           const std::vector<int>& piece_material, int min_rows) {
  int materials = 0;
  for (int m : piece_material) materials = std::max(materials, m + 1);
  std::vector<std::vector<std::span<const double>>> stretches(materials);
  for (std::size_t i = 0; i < pieces.size() && i < piece_material.size(); ++i) {
    if (piece_material[i] < 0 || pieces[i].pair_mu.size() < 3) continue;
    stretches[piece_material[i]].emplace_back(pieces[i].pair_mu);
  }
  std::vector<std::optional<SeriesTexture>> out(materials);
  for (int m = 0; m < materials; ++m) {
    if (absl::StatusOr<SeriesTexture> t = FitSeriesTexture(stretches[m], min_rows); t.ok()) out[m] = *t;
  }
  return out;
}

std::vector<SeriesTexture> FittedTextures(const std::vector<std::optional<SeriesTexture>>& by_material) {
  std::vector<SeriesTexture> out;
  for (const std::optional<SeriesTexture>& t : by_material) {
    if (t.has_value()) out.push_back(*t);
  }
  return out;
}

absl::StatusOr<std::vector<std::vector<MapPiece>>> SplitPiecesAgainst(const std::vector<MapPiece>& pieces,
                                                                      const std::vector<SeriesTexture>& textures,
                                                                      const KnownTextureSplitOptions& options) {
  std::vector<std::vector<MapPiece>> out(pieces.size());
  if (textures.size() < 2) return out;
  for (std::size_t i = 0; i < pieces.size(); ++i) {
    const MapPiece& p = pieces[i];
    if (p.pair_mu.empty()) continue;
    if (p.point_s_mm.size() != p.points.size()) {
      return absl::InvalidArgumentError(absl::StrCat("map piece ", i, ": ", p.point_s_mm.size(),
                                                     " point positions for ", p.points.size(), " points"));
    }
    absl::StatusOr<std::vector<ChangePoint>> changes = FindKnownTextureChanges(p.pair_mu, p.pair_s_mm, textures, options);
    if (!changes.ok()) return Named(changes.status(), i);
    if (changes->empty()) continue;
    absl::StatusOr<std::vector<MapPiece>> parts = Split(p, *changes);
    if (!parts.ok()) return Named(parts.status(), i);
    out[i] = *std::move(parts);
  }
  return out;
}

}  // namespace surfmap
