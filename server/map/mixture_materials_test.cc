#include "server/map/mixture_materials.h"

#include <set>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include "absl/strings/str_cat.h"
#include "server/map/piece_resplit.h"
#include "server/map/testing/map_pieces.h"
#include "server/map/testing/paper_friction.h"

namespace surfmap {
namespace {

using testing::kGlassLike;
using testing::kMasoniteLike;
using testing::kRubberLike;
using testing::kSandpaperLike;
using testing::PieceWithSeries;
using testing::Plate;
using testing::Stretch;

using testing::kRubberMu;
using testing::kMasoniteMu;
using testing::kSandpaperMu;
constexpr int kRubberMaterial = 0, kMasoniteMaterial = 1, kSandpaperMaterial = 2, kTested = 3;

struct Grouped {
  std::vector<MapPiece> pieces;
  std::vector<int> material;
  void Add(const std::vector<Stretch>& stretches, int m, std::uint64_t seed) {
    const double x = static_cast<double>(pieces.size());
    pieces.push_back(PieceWithSeries(static_cast<int>(pieces.size()), {x, 0, 0}, {x, 16, 0}, stretches, seed));
    material.push_back(m);
  }
};

// Ten pure 16 mm drags of each of rubber, masonite and sandpaper, and eight
// drags grouped as a fourth material made of `tested` (their stretches).
Grouped ThreeMaterialsAndATestedOne(const std::vector<Stretch>& tested) {
  Grouped g;
  std::uint64_t seed = 1;
  for (int i = 0; i < 10; ++i) {
    g.Add({{160, kRubberMu, kRubberLike}}, kRubberMaterial, seed++);
    g.Add({{160, kMasoniteMu, kMasoniteLike}}, kMasoniteMaterial, seed++);
    g.Add({{160, kSandpaperMu, kSandpaperLike}}, kSandpaperMaterial, seed++);
  }
  for (int i = 0; i < 8; ++i) g.Add(tested, kTested, seed++);
  return g;
}

std::vector<std::optional<SeriesTexture>> Textures(const Grouped& g) {
  return MaterialTextures(g.pieces, g.material, /*min_rows=*/300);
}

TEST(MixtureMaterialsTest, PiecesThatCrossFromRubberToMasoniteAreDissolved) {
  // Each drag holds 8 mm of rubber then 8 mm of masonite, as drags across a
  // boundary whose change their own test missed: their material reads
  // between the two, in mu and in texture.
  const Grouped g = ThreeMaterialsAndATestedOne({{80, kRubberMu, kRubberLike}, {80, kMasoniteMu, kMasoniteLike}});
  const std::vector<std::optional<SeriesTexture>> textures = Textures(g);
  ASSERT_EQ(textures.size(), 4u);
  ASSERT_TRUE(textures[kTested].has_value());
  EXPECT_GT(textures[kTested]->mean, kRubberMu + 0.01);
  EXPECT_LT(textures[kTested]->mean, kMasoniteMu - 0.01);
  const absl::StatusOr<MixtureScore> score = ScoreMixture(g.pieces, g.material, kTested, textures,
                                                          {kRubberMaterial, kMasoniteMaterial, kSandpaperMaterial}, {});
  ASSERT_TRUE(score.ok()) << score.status();
  EXPECT_GT(score->margin(), 0.0);
  EXPECT_GE(score->cuts, 6) << "most of the eight drags are cut where they cross";
  EXPECT_EQ(MixtureMaterials(g.pieces, g.material, textures, {}).value(), std::vector<int>{kTested});
}

TEST(MixtureMaterialsTest, AMaterialOfItsOwnBetweenTwoOthersStays) {
  // A smooth material whose mu lies between rubber's and masonite's, as the
  // mixture's does: its texture is its own, and the others cannot explain it.
  const Grouped g = ThreeMaterialsAndATestedOne({{160, 0.3325, kGlassLike}});
  const std::vector<std::optional<SeriesTexture>> textures = Textures(g);
  ASSERT_TRUE(textures[kTested].has_value());
  EXPECT_LT(ScoreMixture(g.pieces, g.material, kTested, textures,
                         {kRubberMaterial, kMasoniteMaterial, kSandpaperMaterial}, {})
                .value()
                .margin(),
            0.0);
  EXPECT_TRUE(MixtureMaterials(g.pieces, g.material, textures, {}).value().empty());
}

TEST(MixtureMaterialsTest, EveryMaterialOfTheTruthStays) {
  // Every material is tested: none of the three pure ones is a mixture of
  // the others (and the mixture is found first, then none).
  for (const bool with_mixture : {false, true}) {
    Grouped g = ThreeMaterialsAndATestedOne({{80, kRubberMu, kRubberLike}, {80, kMasoniteMu, kMasoniteLike}});
    if (!with_mixture) {
      for (int& m : g.material) m = m == kTested ? -1 : m;
    }
    const std::vector<int> found = MixtureMaterials(g.pieces, g.material, Textures(g), {}).value();
    EXPECT_EQ(found, with_mixture ? std::vector<int>{kTested} : std::vector<int>{});
  }
}

TEST(MixtureMaterialsTest, NothingIsTestedWithoutTwoOtherTextures) {
  const Grouped g = ThreeMaterialsAndATestedOne({{80, kRubberMu, kRubberLike}, {80, kMasoniteMu, kMasoniteLike}});
  // Rubber and the mixture alone: one other texture cannot cut a piece.
  std::vector<int> two = g.material;
  for (int& m : two) m = m == kMasoniteMaterial || m == kSandpaperMaterial ? -1 : m;
  EXPECT_TRUE(MixtureMaterials(g.pieces, two, MaterialTextures(g.pieces, two, 300), {}).value().empty());
  // A material without a texture (too few rows) is neither tested nor an
  // explanation.
  std::vector<std::optional<SeriesTexture>> textures = Textures(g);
  textures[kTested].reset();
  EXPECT_TRUE(MixtureMaterials(g.pieces, g.material, textures, {}).value().empty());
}

TEST(MixtureMaterialsTest, BadInputIsRefusedByName) {
  Grouped g = ThreeMaterialsAndATestedOne({{80, kRubberMu, kRubberLike}, {80, kMasoniteMu, kMasoniteLike}});
  const std::vector<std::optional<SeriesTexture>> textures = Textures(g);
  const std::vector<int> others = {kRubberMaterial, kMasoniteMaterial};
  auto refused = [](const absl::Status& s, const std::string& naming) {
    return s.code() == absl::StatusCode::kInvalidArgument && s.message().find(naming) != std::string::npos;
  };
  EXPECT_TRUE(refused(ScoreMixture(g.pieces, {0, 1}, kTested, textures, others, {}).status(), "piece materials"));
  EXPECT_TRUE(refused(ScoreMixture(g.pieces, g.material, 7, textures, others, {}).status(), "material 7"));
  EXPECT_TRUE(refused(ScoreMixture(g.pieces, g.material, kTested, textures, {kRubberMaterial, 9}, {}).status(),
                      "explaining material 9"));
  EXPECT_TRUE(refused(ScoreMixture(g.pieces, g.material, kTested, textures, {kRubberMaterial, kTested}, {}).status(),
                      "explaining material 3"));
  // A piece whose pair positions and values differ in size: named.
  g.pieces.back().pair_s_mm.pop_back();
  const absl::Status bad_piece = MixtureMaterials(g.pieces, g.material, textures, {}).status();
  EXPECT_TRUE(refused(bad_piece, absl::StrCat("piece ", g.pieces.size() - 1))) << bad_piece;
}

// The piece with the roughness of its own series (an AR(2) fit, as
// reflection coefficients and innovation sigma), as a drag's fit gives it.
MapPiece WithItsRoughness(MapPiece p) {
  const absl::StatusOr<SeriesTexture> t = FitSeriesTexture({p.pair_mu}, 10);
  if (!t.ok()) return p;
  p.piece.texture.reflection = {t->a1 / (1.0 - t->a2), t->a2};
  p.piece.texture.sigma = std::sqrt(t->innovation_variance);
  p.piece.roughness_rows = static_cast<int>(p.pair_mu.size()) - 2;
  return p;
}

// Rubber drags on the left of the plate, sandpaper on the right, and drags
// across the boundary (x = 0) that hold 8 mm of each with no change found
// (a change so large is found by a drag's own test nearly always; between
// rubber and masonite it is missed often, but there the drags across join
// the masonite on this plate instead of making a material of their own).
std::vector<MapPiece> HalvesAndDragsAcross(int across) {
  std::vector<MapPiece> pieces;
  int drag = 0;
  std::uint64_t seed = 1;
  for (double y : {-20.0, -4.0, 12.0}) {
    for (double x : {-44.0, -36.0, -28.0, -20.0}) {
      pieces.push_back(PieceWithSeries(drag++, {x, y, 0}, {x, y + 15.9, 0}, {{160, kRubberMu, kRubberLike}}, seed++));
      pieces.push_back(PieceWithSeries(drag++, {-x, y, 0}, {-x, y + 15.9, 0}, {{160, kSandpaperMu, kSandpaperLike}}, seed++));
    }
  }
  for (int k = 0; k < across; ++k) {
    const double y = -21.0 + 42.0 * k / std::max(1, across - 1);
    pieces.push_back(PieceWithSeries(drag++, {-8, y, 0}, {7.9, y, 0},
                                     {{80, kRubberMu, kRubberLike}, {80, kSandpaperMu, kSandpaperLike}}, seed++));
  }
  for (MapPiece& p : pieces) p = WithItsRoughness(std::move(p));
  return pieces;
}

int MaterialCount(const RegionMap& map) {
  std::set<int> materials;
  for (const TextureRegion& r : map.regions()) materials.insert(r.material);
  return static_cast<int>(materials.size());
}

TEST(MixtureMaterialsTest, TheMapDissolvesTheMixtureAndDrawsTheTwoMaterialsWhereTheyLie) {
  const SurfaceLevel level = Plate();
  const std::vector<MapPiece> pieces = HalvesAndDragsAcross(8);
  RegionMapOptions options;
  // Without the split, what the grouping alone makes of the drags across.
  options.split_against_materials = false;
  options.dissolve_mixture_materials = false;
  absl::StatusOr<RegionMap> grouped = RegionMap::Create(level, options);
  ASSERT_TRUE(grouped.ok() && grouped->SetPieces(pieces).ok());
  ASSERT_EQ(MaterialCount(*grouped), 3) << "the drags across should group as a third material for this test";

  options.split_against_materials = true;
  for (const bool dissolve : {false, true}) {
    options.dissolve_mixture_materials = dissolve;
    absl::StatusOr<RegionMap> map = RegionMap::Create(level, options);
    ASSERT_TRUE(map.ok() && map->SetPieces(pieces).ok());
    EXPECT_EQ(map->materials_dissolved(), dissolve ? 1 : 0);
    if (!dissolve) continue;
    EXPECT_EQ(MaterialCount(*map), 2);
    EXPECT_GE(map->split_pieces(), 6) << "the drags across are cut where they cross";
    // Either side of the boundary, on the drags across: its own material.
    int right = 0;
    for (double y : {-21.0, -9.0, 3.0, 15.0}) {
      const absl::StatusOr<MapValue> left = map->ValueAtPosition({-5, y, 0});
      const absl::StatusOr<MapValue> right_side = map->ValueAtPosition({5, y, 0});
      ASSERT_TRUE(left.ok() && right_side.ok());
      right += std::abs(left->mu - kRubberMu) < 0.02;
      right += std::abs(right_side->mu - kSandpaperMu) < 0.02;
    }
    EXPECT_GE(right, 7) << "of 8 points 3 mm from the boundary";
  }
}

}  // namespace
}  // namespace surfmap
