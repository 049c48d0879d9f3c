// Materials the others explain: a material made of pieces that straddle the
// boundary between two others.
//
// Where two materials of close friction meet (rubber 0.305 beside masonite
// 0.36 on held_block), a drag across the boundary often shows no change its
// own test can find, and its one piece holds both. Such pieces are alike to
// each other, and the merge rule (texture_regions.h) makes them a material
// of their own, between the two in mu and in texture (0.344; a1 1.1 between
// rubber's 0.6 and masonite's 1.6). The map then draws a fifth material over
// both strips' ground: held_block seed 6 had two of them, and 77.5 % of its
// rubber strip right.
//
// A material m is such a mixture when the other materials explain its pieces
// better than its own texture does, counting what each model is free to
// choose. Each piece of m is split against the other materials' textures
// (FindKnownTextureChanges, known_texture_split.h) and each part scored
// under its likeliest other texture; the same parts are scored under m's:
//
//   without = sum_parts max_(m' != m) log L(part | m') - sum_cuts log(K / alpha)
//   with    = sum_parts log L(part | m) - (4 / 2) log(rows of m)
//
// A cut is paid its own critical value (its search tried K splits); m's
// texture is paid as BIC pays 4 free parameters (mean, a1, a2, innovation
// variance) fitted to these very rows. m is a mixture when without > with.
// On the stored held-out jobs (500 Hz, seeds 3-6) the two held_block
// mixtures scored +17 and +51 while every material of the truth scored -130
// or below; a duplicate of glass made of four pieces that ran onto its
// neighbours scored +296.
#pragma once

#include <optional>
#include <vector>

#include "absl/status/statusor.h"
#include "server/estimate/known_texture_split.h"
#include "server/map/map_piece.h"

namespace surfmap {

struct MixtureScore {
  double without = 0.0;  // the others' explanation, cuts paid
  double with = 0.0;     // the material's own, its texture paid
  int cuts = 0;
  double margin() const { return without - with; }
};

// The score of material `m` (piece_material[i] of pieces[i]; -1 = none)
// against the materials in `others` (indices into `textures`, each fitted).
// Pieces with fewer than three pairs add nothing. Errors
// (INVALID_ARGUMENT): sizes of `pieces` and `piece_material` that differ, an
// `m` or an `others` entry that names no fitted texture (or `m` itself), and
// what the split refuses (a piece whose pair positions and values differ in
// size, naming the piece; invalid split options).
absl::StatusOr<MixtureScore> ScoreMixture(const std::vector<MapPiece>& pieces, const std::vector<int>& piece_material, int m,
                          const std::vector<std::optional<SeriesTexture>>& textures, const std::vector<int>& others,
                          const KnownTextureSplitOptions& split);

// The materials to dissolve, in the order found: the material of largest
// positive margin, then again among the rest with it no longer an
// explanation, until none is positive. Only materials with a texture are
// tested, and only while at least two others have one (a cut needs two).
// Errors: as ScoreMixture's.
absl::StatusOr<std::vector<int>> MixtureMaterials(const std::vector<MapPiece>& pieces, const std::vector<int>& piece_material,
                                  const std::vector<std::optional<SeriesTexture>>& textures,
                                  const KnownTextureSplitOptions& split);

}  // namespace surfmap
