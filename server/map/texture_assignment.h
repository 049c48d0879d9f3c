// Regions moved to the material whose texture explains their pairs best.
//
// Materials are regions grouped by the merge rule (texture_regions.h), whose
// tests accept a short, noisy piece as alike to more than one material: a
// 4 mm masonite piece reads anywhere in 0.30-0.45 with its spread and shape
// known only roughly, so it passes as rubber (0.305) or sandpaper (0.5) as
// readily as masonite, and the greedy merge puts it with whichever it met
// first. On held_vase (seed 2) two single-piece regions of masonite ground
// reported rubber's and sandpaper's friction that way.
//
// Once the materials are known, each has a texture fitted from hundreds of
// pairs (known_texture_split.h); a region's pair series is then evidence of
// its own under every one of them. A region whose material has a texture
// moves to the material m* of greatest likelihood when
//
//   log L(m*) - log L(m) > log((T - 1) / alpha)
//
// T the fitted textures, m its material: if the region is of m's texture,
// each ratio L(m') / L(m) has expectation 1, so by Markov's inequality and
// the union bound over the T - 1 others it moves with probability at most
// alpha. A region whose material has no texture (too few pairs: a single dot
// of its own) has nothing to be tested against and stays.
//
// Only materials the merge rule finds the region alike to are candidates:
// the likelihood chooses among the materials its statistics allow, it does
// not overrule them. A Gaussian likelihood is not robust: one glass piece
// whose end held a few transitional pairs is far less likely under glass's
// tiny innovation variance than under masonite's wide one, and moved there
// (torus_handle, seed 6), its mu known to 1e-4 dragged the masonite
// material's pooled mean from 0.348 to 0.275.
#pragma once

#include <functional>
#include <optional>
#include <vector>

#include "server/estimate/known_texture_split.h"
#include "server/map/map_piece.h"

namespace surfmap {

// The log-likelihood of a region's pair series under a texture: the sum over
// its pieces (indices into `pieces`) of SeriesLogLikelihood.
double RegionLogLikelihood(const std::vector<MapPiece>& pieces, const std::vector<int>& region_pieces,
                           const SeriesTexture& texture);

// Renumbers `material` (per region; -1 = none, kept) 0.. in order of first
// region, none left empty. Returns, per new number, the old one.
std::vector<int> RenumberInOrderOfFirstRegion(std::vector<int>* material);

struct TextureAssignment {
  std::vector<int> material;  // per region, renumbered 0.. in order of first region
  int moved = 0;              // regions moved to another material
};

// `region_pieces[r]`: indices into `pieces` of region r; `region_material[r]`
// its material (0..); `material_texture[m]` material m's texture, if fitted
// (MaterialTextures, piece_resplit.h); `may_join(r, m)` whether region r is
// alike to material m by the merge rule (asked only for m other than r's).
// `false_alarm_probability` is alpha above, in (0, 1). Pieces without a pair
// series add nothing; materials left without regions are dropped from the
// numbering.
TextureAssignment AssignRegionsByTexture(const std::vector<MapPiece>& pieces,
                                         const std::vector<std::vector<int>>& region_pieces,
                                         const std::vector<int>& region_material,
                                         const std::vector<std::optional<SeriesTexture>>& material_texture,
                                         const std::function<bool(int, int)>& may_join,
                                         double false_alarm_probability);

}  // namespace surfmap
