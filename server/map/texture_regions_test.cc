#include "server/map/texture_regions.h"

#include <set>

#include <gtest/gtest.h>

namespace surfmap {
namespace {

PieceStatistics Piece(double mu, double se, double spread, double pairs) { return {mu, se, spread, pairs}; }

std::vector<std::pair<int, int>> AllPairs(int from, int to) {
  std::vector<std::pair<int, int>> out;
  for (int a = from; a < to; ++a) {
    for (int b = a + 1; b < to; ++b) out.emplace_back(a, b);
  }
  return out;
}

TEST(MergeIntoRegions, AlikePiecesThatTouchFormOneRegionUnlikeOnesTwo) {
  // Two glass pieces and two sandpaper pieces in a row: 0-1-2-3.
  const std::vector<PieceStatistics> pieces = {Piece(0.106, 0.001, 0.002, 10), Piece(0.107, 0.001, 0.002, 10),
                                               Piece(0.50, 0.02, 0.05, 10), Piece(0.49, 0.02, 0.05, 10)};
  const std::vector<int> region = MergeIntoRegions(pieces, {{0, 1}, {1, 2}, {2, 3}}, {});
  EXPECT_EQ(region, (std::vector<int>{0, 0, 1, 1}));
}

TEST(MergeIntoRegions, PiecesThatDoNotTouchStayApartHoweverAlike) {
  const std::vector<PieceStatistics> pieces = {Piece(0.106, 0.001, 0.002, 10), Piece(0.106, 0.001, 0.002, 10)};
  EXPECT_EQ(MergeIntoRegions(pieces, {}, {}), (std::vector<int>{0, 1}));
}

TEST(MergeIntoRegions, ACannotLinkKeepsAlikePiecesApartOnlyBeyondTheResolutions) {
  // Rubber and masonite means one drag's noise apart but spreads 3x apart:
  // unlike; a cannot-link between pieces that differ by less than the
  // resolutions is ignored.
  const std::vector<PieceStatistics> far = {Piece(0.30, 0.05, 0.11, 5), Piece(0.33, 0.05, 0.11, 5)};
  EXPECT_EQ(MergeIntoRegions(far, {{0, 1}}, {{0, 1}}), (std::vector<int>{0, 1}));
  const std::vector<PieceStatistics> near = {Piece(0.300, 0.05, 0.11, 5), Piece(0.305, 0.05, 0.12, 5)};
  EXPECT_EQ(MergeIntoRegions(near, {{0, 1}}, {{0, 1}}), (std::vector<int>{0, 0}));
}

TEST(MergeIntoRegions, SpreadsBelowTheFloorAreOneTexture) {
  // Two long glass pieces: the second's per-pair spread 2.5x the first's
  // (0.005: a drag at a lighter load, or next to a change), both below
  // what the map resolves.
  const std::vector<PieceStatistics> glass = {Piece(0.106, 0.0005, 0.002, 100), Piece(0.106, 0.0005, 0.005, 100)};
  RegionMergeOptions no_floor;
  no_floor.spread_floor = 0.0;
  ASSERT_EQ(MergeIntoRegions(glass, {{0, 1}}, {}, no_floor), (std::vector<int>{0, 1}))
      << "without the floor the spreads tell them apart";
  EXPECT_EQ(MergeIntoRegions(glass, {{0, 1}}, {}), (std::vector<int>{0, 0}));
  // A change detected between them is within the resolutions: ignored.
  EXPECT_EQ(MergeIntoRegions(glass, {{0, 1}}, {{0, 1}}), (std::vector<int>{0, 0}));
  // Above the floor a 2.5x spread still tells textures apart.
  const std::vector<PieceStatistics> rough = {Piece(0.30, 0.0005, 0.02, 100), Piece(0.30, 0.0005, 0.05, 100)};
  EXPECT_EQ(MergeIntoRegions(rough, {{0, 1}}, {}), (std::vector<int>{0, 1}));
}

// A piece with a roughness signature: reflection coefficients k1, k2 fitted
// on `rows` values.
PieceStatistics RoughPiece(double mu, double se, double spread, double pairs, double k1, double k2, double rows) {
  PieceStatistics p = Piece(mu, se, spread, pairs);
  p.signature_order = 2;
  p.reflection = {k1, k2, 0.0, 0.0};
  p.reflection_rows = {rows, rows, 0.0, 0.0};
  return p;
}

TEST(MergeIntoRegions, RoughnessKeepsApartTexturesThatMuAndSpreadCannotTellApart) {
  // twin_band_egg's rubber (k 0.8, 0.25) and masonite (k 0.93, -0.73) as
  // 15 mm pieces (150 values a pass) whose mu and spread happen to agree, as
  // a masonite piece's mu can (its texture wanders slowly): alike by mu and
  // spread, 0.98 apart in k2, allowed z f sqrt(0.94 / 150 + 0.47 / 150) =
  // 3.29 x 2 x 0.097 = 0.64 (f = reflection_se_factor).
  const std::vector<PieceStatistics> pieces = {RoughPiece(0.32, 0.02, 0.08, 10, 0.80, 0.25, 150),
                                               RoughPiece(0.33, 0.02, 0.09, 10, 0.93, -0.73, 150)};
  EXPECT_EQ(MergeIntoRegions(pieces, {{0, 1}}, {}), (std::vector<int>{0, 1}));
  // 6 mm pieces (60 values) are not enough alone (allowed 1.0); their
  // regions' pools are (the region map's materials).
  std::vector<PieceStatistics> short_pieces = pieces;
  for (PieceStatistics& p : short_pieces) p.reflection_rows = {60, 60, 0, 0};
  EXPECT_EQ(MergeIntoRegions(short_pieces, {{0, 1}}, {}), (std::vector<int>{0, 0}));
  RegionMergeOptions without;
  without.compare_roughness = false;
  EXPECT_EQ(MergeIntoRegions(pieces, {{0, 1}}, {}, without), (std::vector<int>{0, 0}));
  // One texture's estimates 0.25 apart, known however precisely: below the
  // resolution, one region.
  const std::vector<PieceStatistics> same = {RoughPiece(0.32, 0.02, 0.08, 10, 0.80, 0.25, 10000),
                                             RoughPiece(0.33, 0.02, 0.09, 10, 0.70, 0.00, 10000)};
  EXPECT_EQ(MergeIntoRegions(same, {{0, 1}}, {}), (std::vector<int>{0, 0}));
  // A piece without a fit is judged by mu and spread alone.
  const std::vector<PieceStatistics> unfitted = {RoughPiece(0.32, 0.02, 0.08, 10, 0.80, 0.25, 150),
                                                 Piece(0.33, 0.02, 0.09, 10)};
  EXPECT_EQ(MergeIntoRegions(unfitted, {{0, 1}}, {}), (std::vector<int>{0, 0}));
}

TEST(PoolStatistics, PoolsEachReflectionCoefficientOverThePiecesThatHaveIt) {
  const PieceStatistics pooled = PoolStatistics({RoughPiece(0.3, 0.02, 0.1, 10, 0.8, 0.2, 100),
                                                 RoughPiece(0.3, 0.02, 0.1, 10, 0.6, 0.0, 300),
                                                 Piece(0.3, 0.02, 0.1, 10)});
  ASSERT_EQ(pooled.signature_order, 2);
  EXPECT_DOUBLE_EQ(pooled.reflection[0], (0.8 * 100 + 0.6 * 300) / 400);
  EXPECT_DOUBLE_EQ(pooled.reflection[1], (0.2 * 100 + 0.0 * 300) / 400);
  EXPECT_DOUBLE_EQ(pooled.reflection_rows[0], 400);
  EXPECT_EQ(PoolStatistics({Piece(0.3, 0.02, 0.1, 10)}).signature_order, 0);
}

// A recorded neighbourhood of a map (surfmap-mapsim --scene banded_vase
// --mode boundary --seed 3, estimator 4, before misfits were moved): the
// pieces of the region laid over a masonite patch (truth mu 0.36) and every
// piece touching them (glass 0.106, rubber 0.305 of the band that crosses the
// patch), with the touching pairs and cannot-links the map found. Greedy
// merging carried a 16 mm drag on the rubber band (piece 40) and a piece 70 %
// rubber with an undetected change inside (20) into the patch's region,
// through short noisy masonite pieces: the region read 0.330 and two thirds
// of the patch was classified rubber.
struct Neighbourhood {
  std::vector<PieceStatistics> pieces;
  std::vector<std::pair<int, int>> adjacent, cannot_link;
};

Neighbourhood VasePatch() {
  Neighbourhood n;
  n.pieces = {
      {0.2988, 0.0695, 0.0808, 1.43}, {0.4362, 0.0743, 0.0641, 1.24}, {0.1061, 0.0089, 0.0025, 6.89},
      {0.3591, 0.0374, 0.1182, 9.98}, {0.3004, 0.0147, 0.0200, 1.91}, {0.3454, 0.0754, 0.1093, 2.19},
      {0.1629, 0.1155, 0.1081, 1.00}, {0.1061, 0.0018, 0.0023, 6.75}, {0.1052, 0.0712, 0.0011, 1.00},
      {0.3435, 0.0358, 0.1079, 9.24}, {0.3634, 0.0501, 0.1583, 9.97}, {0.3008, 0.0592, 0.1025, 3.11},
      {0.1063, 0.0055, 0.0024, 6.64}, {0.4169, 0.0771, 0.1409, 3.49}, {0.1059, 0.0091, 0.0020, 6.26},
      {0.1062, 0.0006, 0.0020, 9.91}, {0.1059, 0.0006, 0.0019, 9.96}, {0.1056, 0.0007, 0.0021, 9.94},
      {0.3991, 0.0422, 0.1018, 6.09}, {0.1068, 0.0145, 0.0025, 3.67}, {0.3075, 0.0192, 0.0484, 6.87},
      {0.1055, 0.0126, 0.0030, 2.89}, {0.1063, 0.0071, 0.0021, 5.30}, {0.3116, 0.0549, 0.1140, 4.42},
      {0.2885, 0.0119, 0.0336, 7.92}, {0.1062, 0.0068, 0.0019, 8.88}, {0.4279, 0.2038, 0.1823, 1.00},
      {0.6697, 0.2292, 0.0094, 1.00}, {0.4058, 0.1128, 0.1352, 1.58}, {0.1061, 0.0068, 0.0021, 8.19},
      {0.3283, 0.0579, 0.0991, 3.08}, {0.1057, 0.0062, 0.0020, 6.70}, {0.3116, 0.0093, 0.0293, 9.95},
      {0.1053, 0.0176, 0.0019, 2.97}, {0.3925, 0.0422, 0.1081, 6.80}, {0.1058, 0.0093, 0.0018, 5.38},
      {0.3790, 0.0588, 0.1206, 4.37}, {0.3884, 0.0490, 0.1400, 8.30}, {0.2873, 0.0246, 0.0362, 2.74},
      {0.1064, 0.0049, 0.0021, 6.84}, {0.3167, 0.0154, 0.0422, 7.51}
  };
  n.adjacent = {
      {0, 1}, {0, 10}, {0, 20}, {0, 30}, {0, 31}, {1, 2}, {1, 20}, {1, 31}, {2, 20}, {2, 21}, {2, 31}, {2, 39},
      {2, 40}, {3, 9}, {3, 11}, {3, 13}, {3, 17}, {3, 18}, {3, 23}, {3, 25}, {3, 26}, {3, 27}, {3, 28}, {3, 34},
      {4, 10}, {4, 20}, {4, 24}, {4, 37}, {5, 6}, {5, 37}, {5, 40}, {6, 7}, {6, 37}, {6, 40}, {7, 32}, {7, 37},
      {7, 40}, {8, 9}, {8, 16}, {8, 18}, {8, 35}, {9, 18}, {9, 23}, {9, 35}, {9, 36}, {10, 15}, {10, 20}, {10, 24},
      {10, 30}, {10, 33}, {10, 34}, {11, 12}, {11, 28}, {11, 30}, {11, 34}, {12, 28}, {12, 29}, {12, 30}, {12, 31},
      {13, 14}, {13, 18}, {13, 19}, {13, 28}, {13, 29}, {14, 19}, {14, 29}, {15, 24}, {15, 25}, {15, 33}, {16, 18},
      {16, 19}, {16, 35}, {17, 22}, {17, 23}, {17, 25}, {18, 19}, {20, 21}, {20, 37}, {20, 40}, {21, 40}, {22, 23},
      {22, 35}, {22, 36}, {23, 36}, {25, 26}, {25, 27}, {25, 33}, {25, 34}, {26, 27}, {26, 34}, {27, 34}, {28, 29},
      {30, 31}, {30, 34}, {31, 39}, {32, 38}, {32, 40}, {33, 34}, {35, 36}, {37, 40}, {38, 39}, {38, 40}, {39, 40}
  };
  n.cannot_link = {
      {0, 1}, {1, 2}, {5, 6}, {6, 7}, {8, 9}, {11, 12}, {13, 14}, {18, 19}, {20, 21}, {22, 23}, {25, 26}, {26, 27},
      {28, 29}, {30, 31}, {33, 34}, {35, 36}, {38, 39}
  };
  return n;
}

constexpr int kRubberDrag = 40;
// The pieces of the patch's region that lie on masonite.
const std::vector<int> kMasonite = {0, 3, 6, 9, 10, 11, 13, 18, 23, 26, 28, 30, 34, 36};

TEST(MergeIntoRegions, AChainOfNoisyPiecesDoesNotCarryAnotherTextureIntoARegion) {
  const Neighbourhood n = VasePatch();
  const std::vector<int> region = MergeIntoRegions(n.pieces, n.adjacent, n.cannot_link);
  // The longest masonite piece's region holds the patch's long pieces.
  const int patch = region[3];
  for (int i : {3, 9, 26, 34}) EXPECT_EQ(region[i], patch) << "piece " << i;
  EXPECT_NE(region[kRubberDrag], patch);
  // Its mean is masonite's: within two standard errors (~0.013 each) of the
  // pure masonite pieces' pooled mean; it was 0.330.
  std::vector<PieceStatistics> members, masonite;
  for (int i = 0; i < static_cast<int>(n.pieces.size()); ++i) {
    if (region[i] == patch) members.push_back(n.pieces[i]);
  }
  for (int i : kMasonite) masonite.push_back(n.pieces[i]);
  const PieceStatistics pure = PoolStatistics(masonite);
  EXPECT_NEAR(PoolStatistics(members).mu, pure.mu, 2.0 * pure.mu_se);
  EXPECT_GT(PoolStatistics(members).mu, 0.3325);  // the midpoint between rubber and masonite
  // Every piece is alike to the rest of its region.
  for (int r : std::set<int>(region.begin(), region.end())) {
    for (int i = 0; i < static_cast<int>(n.pieces.size()); ++i) {
      if (region[i] != r) continue;
      std::vector<PieceStatistics> rest;
      for (int j = 0; j < static_cast<int>(n.pieces.size()); ++j) {
        if (j != i && region[j] == r) rest.push_back(n.pieces[j]);
      }
      if (rest.empty()) continue;
      EXPECT_TRUE(TexturesAlike(n.pieces[i], PoolStatistics(rest), {})) << "piece " << i;
    }
  }
}

TEST(MergeIntoRegions, PiecesOfOneMaterialStayOneRegion) {
  // The glass pieces of the neighbourhood, all touching: one region, however
  // many passes look for misfits to move.
  const Neighbourhood n = VasePatch();
  std::vector<PieceStatistics> glass;
  for (const PieceStatistics& p : n.pieces) {
    if (p.mu < 0.11) glass.push_back(p);
  }
  ASSERT_GE(glass.size(), 15u);
  const std::vector<int> region = MergeIntoRegions(glass, AllPairs(0, static_cast<int>(glass.size())), {});
  EXPECT_EQ(std::set<int>(region.begin(), region.end()).size(), 1u);
}

}  // namespace
}  // namespace surfmap
