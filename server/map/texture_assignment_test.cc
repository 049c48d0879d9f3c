#include "server/map/texture_assignment.h"

#include <algorithm>
#include <functional>
#include <span>
#include <optional>
#include <vector>

#include <gtest/gtest.h>
#include "server/estimate/series_for_test.h"
#include "server/map/testing/paper_friction.h"

namespace surfmap {
namespace {

using testing::kGlassLike;
using testing::kMasoniteLike;
using testing::kRubberLike;
using testing::kSandpaperLike;
using testing::Series;

// The merge rule allowing every move (the tests of the likelihood alone).
const std::function<bool(int, int)> kAny = [](int, int) { return true; };

using testing::kGlassMu;
using testing::kRubberMu;
using testing::kMasoniteMu;
using testing::kSandpaperMu;

MapPiece PieceOf(int pairs, double mean, const ArParams& texture, std::uint64_t seed) {
  MapPiece p;
  p.pair_mu = Series({{pairs, mean, texture}}, seed);
  for (std::size_t i = 0; i < p.pair_mu.size(); ++i) p.pair_s_mm.push_back(0.1 * i);
  return p;
}

// Materials 0..3 (glass, rubber, masonite, sandpaper), each from four 16 mm
// drags, their textures fitted from those drags alone; each drag is a region
// of its material (regions 0..15), and more may be added.
struct FourMaterials {
  std::vector<MapPiece> pieces;
  std::vector<std::optional<SeriesTexture>> textures;
  std::vector<std::vector<int>> regions;
  std::vector<int> material;

  explicit FourMaterials(std::uint64_t seed) {
    const double means[] = {kGlassMu, kRubberMu, kMasoniteMu, kSandpaperMu};
    const ArParams* kinds[] = {&kGlassLike, &kRubberLike, &kMasoniteLike, &kSandpaperLike};
    for (int m = 0; m < 4; ++m) {
      std::vector<std::span<const double>> stretches;
      for (int d = 0; d < 4; ++d) pieces.push_back(PieceOf(160, means[m], *kinds[m], seed * 100 + m * 10 + d));
      for (int d = 0; d < 4; ++d) stretches.emplace_back(pieces[pieces.size() - 4 + d].pair_mu);
      textures.push_back(*FitSeriesTexture(stretches));
    }
    for (int i = 0; i < 16; ++i) Add(std::nullopt, i / 4);
  }
  // A region of one piece (the next drag, or `piece` appended) in material m.
  void Add(std::optional<MapPiece> piece, int m) {
    if (piece.has_value()) pieces.push_back(*std::move(piece));
    regions.push_back({static_cast<int>(regions.size())});
    material.push_back(m);
  }
  TextureAssignment Assign(const std::function<bool(int, int)>& may_join = kAny) const {
    return AssignRegionsByTexture(pieces, regions, material, textures, may_join, 0.05);
  }
};

TEST(TextureAssignmentTest, AShortMasonitePieceLeavesRubberForMasonite) {
  FourMaterials map(1);
  map.Add(PieceOf(40, kMasoniteMu, kMasoniteLike, 7), 1);  // 4 mm of masonite the merge rule put with rubber
  const TextureAssignment a = map.Assign();
  EXPECT_EQ(a.moved, 1);
  std::vector<int> expected = map.material;
  expected.back() = 2;
  EXPECT_EQ(a.material, expected);
}

// Over many seeds: how often a short piece leaves its own material (bounded
// by alpha when the textures are right; here they are fitted from 632 rows
// each), and how often a short piece of another texture leaves the one it
// was wrongly put with.
TEST(TextureAssignmentTest, RatesAtTheDefault) {
  constexpr int kTrials = 400;
  const double kMeans[] = {kGlassMu, kRubberMu, kMasoniteMu, kSandpaperMu};
  const ArParams* kKinds[] = {&kGlassLike, &kRubberLike, &kMasoniteLike, &kSandpaperLike};
  int false_moves = 0, wrong_left = 0, wrong_trials = 0;
  for (int t = 0; t < kTrials; ++t) {
    FourMaterials map(1000 + t);
    const int truth = t % 4;
    // 3 mm of `truth` in its own material, and 3 mm of it in the next one.
    map.Add(PieceOf(30, kMeans[truth], *kKinds[truth], 5000 + t), truth);
    map.Add(PieceOf(30, kMeans[truth], *kKinds[truth], 9000 + t), (truth + 1) % 4);
    const TextureAssignment a = map.Assign();
    false_moves += a.material[16] != truth;
    for (int r = 0; r < 16; ++r) false_moves += a.material[r] != r / 4;
    ++wrong_trials;
    wrong_left += a.material[17] == truth;
  }
  // 17 regions of their own texture per trial, 6,800 in all: the bound
  // allows alpha (5 %) of them to move; measured 0 (the bound is loose, as
  // the split's). More than a few means the test lost its margin.
  EXPECT_LE(false_moves, 4) << false_moves;
  // Measured: 3 mm of one paper texture put with another is moved to its own
  // in 397 of 400 trials.
  EXPECT_GE(wrong_left, wrong_trials * 0.95) << wrong_left << " of " << wrong_trials;
}

TEST(TextureAssignmentTest, WithoutTexturesRegionsStayAndEmptyMaterialsAreDropped) {
  FourMaterials map(3);
  // Masonite has no texture: its regions have nothing to be tested against,
  // and no region may move to it.
  map.textures[2].reset();
  map.Add(PieceOf(40, kMasoniteMu, kMasoniteLike, 11), 2);
  TextureAssignment a = map.Assign();
  EXPECT_EQ(a.moved, 0);
  EXPECT_EQ(a.material, map.material);

  // A material whose only region moves away is dropped from the numbering:
  // the masonite piece alone in a fifth material, whose texture is rubber's.
  map.textures[2] = *FitSeriesTexture({map.pieces[8].pair_mu, map.pieces[9].pair_mu, map.pieces[10].pair_mu});
  map.material.back() = 4;
  map.textures.push_back(map.textures[1]);
  a = map.Assign();
  EXPECT_EQ(a.moved, 1);
  EXPECT_EQ(a.material.back(), 2);
  EXPECT_EQ(*std::max_element(a.material.begin(), a.material.end()), 3);
}

TEST(TextureAssignmentTest, OnlyMaterialsTheMergeRuleAllowsAreCandidates) {
  FourMaterials map(5);
  map.Add(PieceOf(40, kMasoniteMu, kMasoniteLike, 13), 1);  // masonite put with rubber
  // The merge rule rules masonite out: the piece may not go there, however
  // well its texture fits.
  std::vector<int> asked;
  const TextureAssignment a = map.Assign([&](int r, int m) {
    if (r == 16) asked.push_back(m);
    return m != 2;
  });
  EXPECT_NE(a.material[16], 2);
  EXPECT_EQ(asked, (std::vector<int>{0, 2, 3}));  // never its own
}

TEST(TextureAssignmentTest, PiecesWithoutSeriesAndFewTexturesChangeNothing) {
  FourMaterials map(4);
  map.Add(PieceOf(40, kMasoniteMu, kMasoniteLike, 17), 1);  // would move, with series and textures
  ASSERT_EQ(map.Assign().moved, 1);
  FourMaterials bare = map;
  for (MapPiece& p : bare.pieces) p = MapPiece{};  // no pair series at all
  EXPECT_EQ(bare.Assign().moved, 0);
  EXPECT_EQ(bare.Assign().material, map.material);
  FourMaterials one = map;
  for (int m = 1; m < 4; ++m) one.textures[m].reset();  // a single texture: nothing to choose between
  EXPECT_EQ(one.Assign().moved, 0);
}

}  // namespace
}  // namespace surfmap
