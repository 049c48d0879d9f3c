#include "server/map/map_piece.h"

#include <cstddef>

namespace surfmap {

void PlaceAlong(const LineSample& line, double from, double to, MapPiece* piece) {
  piece->points = line.PointsBetween(from, to);
  piece->point_s_mm.clear();
  if (piece->points.empty()) {
    piece->points.push_back(line.PointAt(from));
    piece->point_s_mm.push_back(from);
    return;
  }
  // The positions of PointsBetween's points: both ends and the path's points
  // between them.
  piece->point_s_mm.push_back(from);
  for (double s : line.path_s_mm) {
    if (s > from && s < to) piece->point_s_mm.push_back(s);
  }
  if (to > from) piece->point_s_mm.push_back(to);
}

std::vector<MapPiece> MapPiecesOf(const LineSample& line, int drag, const Eigen::Vector3d& site_position) {
  std::vector<MapPiece> out;
  for (std::size_t k = 0; k < line.pieces.size(); ++k) {
    const LinePiece& piece = line.pieces[k];
    MapPiece p;
    p.drag = drag;
    p.line_piece = static_cast<int>(k);
    p.piece = piece;
    if (line.path_s_mm.empty()) {
      p.points = {site_position};
      out.push_back(std::move(p));
      continue;
    }
    PlaceAlong(line, piece.start_mm, piece.end_mm, &p);
    // The piece's own pairs: those inside its extent, less the transitional
    // pair next to a change (the change lies midway between two pairs).
    std::size_t first = 0;
    while (first < line.pair_s_mm.size() && line.pair_s_mm[first] < piece.start_mm) ++first;
    std::size_t end = first;
    while (end < line.pair_s_mm.size() && line.pair_s_mm[end] <= piece.end_mm) ++end;
    if (piece.starts_at_change && first < end) ++first;
    if (piece.ends_at_change && end > first) --end;
    p.pair_s_mm.assign(line.pair_s_mm.begin() + first, line.pair_s_mm.begin() + end);
    p.pair_mu.assign(line.pair_mu.begin() + first, line.pair_mu.begin() + end);
    out.push_back(std::move(p));
  }
  return out;
}

}  // namespace surfmap
