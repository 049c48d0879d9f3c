// One pure piece of one drag, placed on the object: what the region map is
// built from.
#pragma once

#include <vector>

#include <Eigen/Core>
#include "server/estimate/line_sample.h"

namespace surfmap {

struct MapPiece {
  int drag = -1;                        // pieces with the same id are one drag, in path order
  // Which of the drag's LineSample::pieces this is (or a part of: the map
  // splits a piece where its series shows a change between two of the map's
  // materials, piece_resplit.h); -1 for a piece made by hand. Lets a reader
  // of the map trace a region's estimate back to the fits behind it.
  int line_piece = -1;
  bool split_by_map = false;            // a part of line_piece, cut by the map
  std::vector<Eigen::Vector3d> points;  // along its extent (>= 1; a point sample has one), mm
  std::vector<double> point_s_mm;       // of each point along the drag's path (empty for a point sample)
  LinePiece piece;                      // texture, mu_se, effective pairs, change flags
  // The per-pair friction series of the piece's own pairs (the transitional
  // pair next to a change left out); empty when the line sample has none.
  std::vector<double> pair_s_mm;
  std::vector<double> pair_mu;
};

// Sets piece->points and piece->point_s_mm to the stretch [from, to] of
// `line`'s path (LineSample::PointsBetween and the positions of its points).
void PlaceAlong(const LineSample& line, double from, double to, MapPiece* piece);

// The pieces of a line sample as map pieces (the path between each piece's
// ends). A line sample without a path (an old fit) gives one piece at
// `site_position`.
std::vector<MapPiece> MapPiecesOf(const LineSample& line, int drag, const Eigen::Vector3d& site_position);

}  // namespace surfmap
