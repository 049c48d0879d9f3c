// Splitting a map's pieces where their series shows a change between two of
// the map's materials that the drag's own change test missed
// (estimate/known_texture_split.h). Between rubber and masonite one drag's
// test finds a change in about 2 drags of 3; a piece that holds both then
// carries one material's region over the other's ground and blends their
// mu (twin_band_egg's masonite band read 0.325 for 0.36 from such pieces).
#pragma once

#include <optional>
#include <vector>

#include "absl/status/statusor.h"
#include "server/estimate/known_texture_split.h"
#include "server/map/map_piece.h"

namespace surfmap {

// The series texture of each material (piece_material[i] of pieces[i], 0..;
// -1 = none), fitted from its pieces' pair series, indexed by material;
// empty for materials with fewer than `min_rows` rows (or whose fit fails).
std::vector<std::optional<SeriesTexture>> MaterialTextures(const std::vector<MapPiece>& pieces,
                                                           const std::vector<int>& piece_material, int min_rows);

// The textures that were fitted, in material order.
std::vector<SeriesTexture> FittedTextures(const std::vector<std::optional<SeriesTexture>>& by_material);

// Per piece: empty where it is kept whole (no series, too short, or no change
// found), otherwise its sub-pieces in path order, with the friction
// statistics of their own pairs (drag_pieces.h), change flags at the new
// changes, and no roughness (a sub-piece's fit was never made). Errors
// (INVALID_ARGUMENT, naming the piece): a piece whose pair series or point
// positions are malformed (RegionMap::SetPieces validates them first).
absl::StatusOr<std::vector<std::vector<MapPiece>>> SplitPiecesAgainst(const std::vector<MapPiece>& pieces,
                                                      const std::vector<SeriesTexture>& textures,
                                                      const KnownTextureSplitOptions& options);

}  // namespace surfmap
