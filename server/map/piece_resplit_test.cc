#include "server/map/piece_resplit.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <string>

#include <gtest/gtest.h>
#include "server/estimate/series_for_test.h"
#include "server/map/region_map.h"
#include "server/map/testing/map_pieces.h"
#include "server/map/testing/paper_friction.h"

namespace surfmap {
namespace {

using testing::kRubberLike;
using testing::kMasoniteLike;
using testing::PieceWithSeries;
using testing::Plate;
using testing::Stretch;
using testing::StraightPiece;

using testing::kRubberMu;
using testing::kMasoniteMu;

// The mean of the pieces' mu weighted by 1 / mu_se^2, as a material pools it.
double PrecisionWeightedMu(const std::vector<MapPiece>& pieces, const std::vector<int>& which) {
  double weight = 0.0, weighted_mu = 0.0;
  for (int i : which) {
    const double w = 1.0 / (pieces[i].piece.mu_se * pieces[i].piece.mu_se);
    weight += w;
    weighted_mu += w * pieces[i].piece.texture.mu;
  }
  return weighted_mu / weight;
}

// Rubber drags on the left half of the plate, masonite on the right, and one
// drag across the middle that holds 8 mm of each with no change detected.
std::vector<MapPiece> HalvesAndOneMixedDrag() {
  std::vector<MapPiece> pieces;
  int drag = 0;
  std::uint64_t seed = 1;
  for (double x : {-40.0, -32.0, -24.0, -16.0}) {
    pieces.push_back(PieceWithSeries(drag++, {x, -8, 0}, {x, 7.9, 0}, {{160, kRubberMu, kRubberLike}}, seed++));
  }
  for (double x : {16.0, 24.0, 32.0, 40.0}) {
    pieces.push_back(PieceWithSeries(drag++, {x, -8, 0}, {x, 7.9, 0}, {{160, kMasoniteMu, kMasoniteLike}}, seed++));
  }
  pieces.push_back(PieceWithSeries(drag++, {-8, 0, 0}, {7.9, 0, 0},
                                   {{80, kRubberMu, kRubberLike}, {80, kMasoniteMu, kMasoniteLike}}, seed++));
  pieces.back().line_piece = 0;  // its drag's fit found one piece
  return pieces;
}

TEST(PieceResplitTest, MaterialTexturesNeedEnoughRows) {
  const std::vector<MapPiece> pieces = HalvesAndOneMixedDrag();
  std::vector<int> material = {0, 0, 0, 0, 1, 1, 1, 1, -1};
  const std::vector<SeriesTexture> textures = FittedTextures(MaterialTextures(pieces, material, 300));
  ASSERT_EQ(textures.size(), 2u);
  // 632 rows of each: the means within the wander of a few drags' texture.
  EXPECT_NEAR(textures[0].mean, kRubberMu, 0.02);
  EXPECT_NEAR(textures[1].mean, kMasoniteMu, 0.03);
  EXPECT_EQ(FittedTextures(MaterialTextures(pieces, material, 1000)).size(), 0u);
  // A material short of rows keeps its place, empty.
  material = {0, 0, 0, 0, 1, -1, -1, -1, -1};
  const std::vector<std::optional<SeriesTexture>> by_material = MaterialTextures(pieces, material, 300);
  ASSERT_EQ(by_material.size(), 2u);
  EXPECT_TRUE(by_material[0].has_value());
  EXPECT_FALSE(by_material[1].has_value());
}

TEST(PieceResplitTest, TheMixedDragIsSplitWhereItCrossesAndTheMapFollows) {
  const SurfaceLevel level = Plate();
  for (const bool split : {true, false}) {
    RegionMapOptions options;
    options.split_against_materials = split;
    auto map = RegionMap::Create(level, options);
    ASSERT_TRUE(map.ok()) << map.status();
    ASSERT_TRUE(map->SetPieces(HalvesAndOneMixedDrag()).ok());
    EXPECT_EQ(map->split_pieces(), split ? 1 : 0);
    EXPECT_EQ(map->pieces().size(), split ? 10u : 9u);
    if (!split) continue;
    // The parts: the change within 1 mm of the drag's middle (7.95 mm
    // along it), each part in its own material's region.
    const MapPiece& left = map->pieces()[8];
    const MapPiece& right = map->pieces()[9];
    EXPECT_NEAR(left.piece.end_mm, 7.95, 1.0);
    EXPECT_TRUE(left.piece.ends_at_change);
    EXPECT_TRUE(right.piece.starts_at_change);
    EXPECT_FALSE(left.piece.has_roughness());
    // Both parts say which piece of which drag they were cut from.
    for (const MapPiece* part : {&left, &right}) {
      EXPECT_EQ(part->drag, 8);
      EXPECT_EQ(part->line_piece, 0);
      EXPECT_TRUE(part->split_by_map);
    }
    EXPECT_FALSE(map->pieces()[0].split_by_map);
    EXPECT_EQ(map->piece_region()[8], map->piece_region()[0]);
    EXPECT_EQ(map->piece_region()[9], map->piece_region()[4]);
    const absl::StatusOr<MapValue> at_left = map->ValueAtPosition({-5, 0, 0});
    const absl::StatusOr<MapValue> at_right = map->ValueAtPosition({5, 0, 0});
    ASSERT_TRUE(at_left.ok() && at_right.ok());
    EXPECT_EQ(at_left->region, map->piece_region()[0]);
    EXPECT_EQ(at_right->region, map->piece_region()[4]);
  }
}

TEST(PieceResplitTest, APlanAddingDragsKeepsTheSplit) {
  // The plan calls SetPieces with one more drag each time: the pieces given
  // before are recognised though the map holds their parts.
  const SurfaceLevel level = Plate();
  auto map = RegionMap::Create(level);
  ASSERT_TRUE(map.ok());
  std::vector<MapPiece> pieces = HalvesAndOneMixedDrag();
  ASSERT_TRUE(map->SetPieces(pieces).ok());
  pieces.push_back(PieceWithSeries(100, {-40, 15, 0}, {-24.1, 15, 0}, {{160, kRubberMu, kRubberLike}}, 77));
  ASSERT_TRUE(map->SetPieces(pieces).ok());
  EXPECT_EQ(map->split_pieces(), 1);
  EXPECT_EQ(map->pieces().size(), 11u);
}

// A 6 mm rubber strip along y (|x| < 3) through masonite: rubber drags
// along the strip, masonite drags either side, and one drag across the
// strip that holds 5 mm of masonite, 5.5 mm of rubber and 5.5 mm of
// masonite with no change detected (big_block_m seed 2's drag 168).
std::vector<MapPiece> StripAndOneDragAcrossIt() {
  std::vector<MapPiece> pieces;
  int drag = 0;
  std::uint64_t seed = 31;
  for (double y : {-20.0, -4.0, 12.0}) {
    pieces.push_back(PieceWithSeries(drag++, {0, y, 0}, {0, y + 15.9, 0}, {{160, kRubberMu, kRubberLike}}, seed++));
  }
  for (double x : {-24.0, -14.0, 14.0, 24.0}) {
    pieces.push_back(PieceWithSeries(drag++, {x, -8, 0}, {x, 7.9, 0}, {{160, kMasoniteMu, kMasoniteLike}}, seed++));
  }
  pieces.push_back(PieceWithSeries(
      drag++, {-7.75, 0, 0}, {8.15, 0, 0},
      {{50, kMasoniteMu, kMasoniteLike}, {55, kRubberMu, kRubberLike}, {55, kMasoniteMu, kMasoniteLike}}, seed++));
  pieces.back().line_piece = 0;
  return pieces;
}

TEST(PieceResplitTest, ADragAcrossAStripIsCutAtBothEdges) {
  const SurfaceLevel level = Plate();
  for (const bool bands : {true, false}) {
    RegionMapOptions options;
    options.known_split.test_bands = bands;
    auto map = RegionMap::Create(level, options);
    ASSERT_TRUE(map.ok()) << map.status();
    ASSERT_TRUE(map->SetPieces(StripAndOneDragAcrossIt()).ok());
    // Single splits leave the drag whole: each side of any one cut holds
    // both materials.
    if (!bands) {
      EXPECT_EQ(map->split_pieces(), 0);
      continue;
    }
    EXPECT_EQ(map->split_pieces(), 1);
    ASSERT_EQ(map->pieces().size(), 10u);
    // The edges lie at 4.95 and 10.45 mm along the drag (x = -2.8 and
    // 2.7); within 1 mm each, the middle part in the rubber's region.
    const MapPiece& middle = map->pieces()[8];
    EXPECT_NEAR(middle.piece.start_mm, 4.95, 1.0);
    EXPECT_NEAR(middle.piece.end_mm, 10.45, 1.0);
    EXPECT_EQ(map->piece_region()[8], map->piece_region()[0]);
    EXPECT_EQ(map->piece_region()[7], map->piece_region()[3]);
    EXPECT_EQ(map->piece_region()[9], map->piece_region()[5]);
    const absl::StatusOr<MapValue> on_strip = map->ValueAtPosition({0, 0, 0});
    ASSERT_TRUE(on_strip.ok());
    EXPECT_EQ(on_strip->region, map->piece_region()[0]);
  }
}

TEST(PieceResplitTest, MalformedSeriesOrPositionsAreRefusedByName) {
  const SurfaceLevel level = testing::Plate();
  auto map = RegionMap::Create(level);
  ASSERT_TRUE(map.ok());
  auto refused = [&](auto&& damage, const std::string& expected) {
    std::vector<MapPiece> pieces = HalvesAndOneMixedDrag();
    damage(pieces[8]);
    const absl::Status status = map->SetPieces(pieces);
    EXPECT_EQ(status.code(), absl::StatusCode::kInvalidArgument) << expected;
    EXPECT_NE(status.message().find(expected), std::string::npos) << status;
  };
  refused([](MapPiece& p) { p.point_s_mm.push_back(20.0); }, "map piece 8: 3 point positions but 2 points");
  refused([](MapPiece& p) { p.point_s_mm.clear(); }, "map piece 8: has a pair series but no point positions");
  refused([](MapPiece& p) { p.point_s_mm = {5.0, 1.0}; }, "map piece 8: point position 1 is not increasing");
  refused([](MapPiece& p) { p.pair_mu[3] = std::nan(""); }, "map piece 8: pair 3 is not finite");
  refused([](MapPiece& p) { p.pair_mu.pop_back(); }, "map piece 8: 160 pair positions but 159 pair values");
  // Nothing was lost: the good pieces still build the map.
  EXPECT_TRUE(map->SetPieces(HalvesAndOneMixedDrag()).ok());
  EXPECT_EQ(map->split_pieces(), 1);
}

// Masonite drags on the right half of the plate with, among them, one piece
// known precisely (se 0.005) that reads 0.40 with rubber's texture: alike to
// masonite by the merge rule only because it has one independent pair, it
// joins the masonite region and, by precision, would take over the
// material's mean (0.397 for the masonite drags' 0.364). Rubber drags on the
// left give a second texture, which explains its series far better than
// masonite's does.
struct IntruderScene {
  std::vector<MapPiece> pieces;
  std::vector<int> rubber, masonite;
  int intruder = -1;
};
IntruderScene RubberMasoniteAndAnIntruder() {
  IntruderScene scene;
  int drag = 0;
  std::uint64_t seed = 11;
  for (double x : {-40.0, -32.0, -24.0, -16.0}) {
    scene.rubber.push_back(drag);
    scene.pieces.push_back(PieceWithSeries(drag++, {x, -8, 0}, {x, 7.9, 0}, {{160, kRubberMu, kRubberLike}}, seed++));
  }
  for (double x : {16.0, 24.0, 32.0, 40.0}) {
    scene.masonite.push_back(drag);
    scene.pieces.push_back(
        PieceWithSeries(drag++, {x, -8, 0}, {x, 7.9, 0}, {{160, kMasoniteMu, kMasoniteLike}}, seed++));
  }
  scene.intruder = drag;
  scene.pieces.push_back(PieceWithSeries(drag++, {28, -8, 0}, {28, 7.9, 0}, {{160, 0.40, kRubberLike}}, seed++));
  scene.pieces.back().piece.effective_pairs = 1.0;
  scene.pieces.back().piece.mu_se = 0.005;
  return scene;
}

TEST(MisfitPieceTest, APieceAnotherTextureExplainsIsLeftOutOfItsMaterialsMu) {
  const IntruderScene scene = RubberMasoniteAndAnIntruder();
  const std::vector<MapPiece>& pieces = scene.pieces;
  const std::vector<int>& masonite = scene.masonite;
  const int intruder = scene.intruder;
  const SurfaceLevel level = Plate();
  for (const bool exclude : {true, false}) {
    RegionMapOptions options;
    options.exclude_misfit_pieces_from_mu = exclude;
    options.move_misfit_pieces = false;  // stays in the region: MisfitPieceTest.* below moves it
    auto map = RegionMap::Create(level, options);
    ASSERT_TRUE(map.ok()) << map.status();
    ASSERT_TRUE(map->SetPieces(pieces).ok());
    ASSERT_EQ(map->piece_region()[intruder], map->piece_region()[masonite[1]]) << "the intruder joins masonite";
    const TextureRegion& region = map->regions()[map->piece_region()[intruder]];
    const bool counted = std::count(region.mu_pieces.begin(), region.mu_pieces.end(), intruder) > 0;
    EXPECT_EQ(counted, !exclude);
    if (exclude) {
      EXPECT_NEAR(region.statistics.mu, PrecisionWeightedMu(pieces, masonite), 1e-12) << "the masonite drags alone";
    } else {
      EXPECT_GT(region.statistics.mu, 0.38) << "the intruder's precision takes the mean";
    }
  }
}

// Rubber drags on the left half of the plate, masonite drags on the right,
// and among the masonite drags two precise pieces of rubber's mu and
// texture that the merge rule lets into the masonite region (each has one
// independent pair). Moved, each is a region of its own of rubber's
// material and the map reads rubber where it lies. Kept in the region (the
// build before), the map reads masonite there. Either way each material's mu
// is its own drags' alone.
TEST(MisfitPieceTest, APieceAnotherTextureExplainsIsMovedToThatMaterial) {
  std::vector<MapPiece> pieces;
  int drag = 0;
  std::uint64_t seed = 31;
  std::vector<int> rubber, masonite, intruders;
  for (double x : {-40.0, -32.0, -24.0, -16.0}) {
    rubber.push_back(drag);
    pieces.push_back(PieceWithSeries(drag++, {x, -8, 0}, {x, 7.9, 0}, {{160, kRubberMu, kRubberLike}}, seed++));
  }
  for (double x : {16.0, 24.0, 32.0, 40.0}) {
    masonite.push_back(drag);
    pieces.push_back(PieceWithSeries(drag++, {x, -8, 0}, {x, 7.9, 0}, {{160, kMasoniteMu, kMasoniteLike}}, seed++));
  }
  for (double x : {20.0, 28.0}) {
    intruders.push_back(drag);
    pieces.push_back(PieceWithSeries(drag++, {x, -8, 0}, {x, 7.9, 0}, {{160, kRubberMu, kRubberLike}}, seed++));
    pieces.back().piece.effective_pairs = 1.0;
    pieces.back().piece.mu_se = 0.01;
  }
  const SurfaceLevel level = Plate();
  for (const bool move : {true, false}) {
    SCOPED_TRACE(move ? "moved" : "kept in its region");
    RegionMapOptions options;
    options.move_misfit_pieces = move;
    auto map = RegionMap::Create(level, options);
    ASSERT_TRUE(map.ok()) << map.status();
    ASSERT_TRUE(map->SetPieces(pieces).ok());
    ASSERT_EQ(map->pieces().size(), pieces.size()) << "no piece was split";
    const auto& regions = map->regions();
    const int rubber_material = regions[map->piece_region()[rubber[0]]].material;
    const int masonite_material = regions[map->piece_region()[masonite[0]]].material;
    ASSERT_NE(rubber_material, masonite_material);
    EXPECT_EQ(map->pieces_moved_by_texture(), move ? 2 : 0);
    for (int i : intruders) {
      const int region = map->piece_region()[i];
      EXPECT_EQ(regions[region].material, move ? rubber_material : masonite_material) << "piece " << i;
      if (move) {
        EXPECT_EQ(regions[region].pieces, std::vector<int>{i}) << "a region of its own";
      }
      // The map's value midway along the intruder, 4 mm from the masonite drags beside it.
      absl::StatusOr<MapValue> value = map->ValueAtPosition(pieces[i].points.front() + Eigen::Vector3d(0, 8, 0));
      ASSERT_TRUE(value.ok()) << value.status();
      EXPECT_NEAR(value->mu, move ? kRubberMu : kMasoniteMu, 0.02) << "piece " << i;
    }
    // Moved or left out, the intruders count in neither material's mu.
    EXPECT_NEAR(regions[map->piece_region()[masonite[0]]].statistics.mu, PrecisionWeightedMu(pieces, masonite), 1e-12);
    EXPECT_NEAR(regions[map->piece_region()[rubber[0]]].statistics.mu, PrecisionWeightedMu(pieces, rubber), 1e-12);
    // Their pieces number every piece once.
    std::vector<int> all;
    for (const TextureRegion& r : regions) all.insert(all.end(), r.pieces.begin(), r.pieces.end());
    std::sort(all.begin(), all.end());
    std::vector<int> expected(pieces.size());
    std::iota(expected.begin(), expected.end(), 0);
    EXPECT_EQ(all, expected);
  }
}

// The first test's intruder: rubber's texture, but a mu of 0.40 known to
// 0.005, which no merge rule calls rubber's (0.305). Rubber's texture
// explains its series best, so it counts in no material's mu; with
// move_only_to_alike_material it stays in the masonite region it joined and
// the map reads masonite where it lies; without it (the build before) it
// moves to rubber and the map reads 0.305 over a piece that measured 0.40.
TEST(MisfitPieceTest, APieceMovesOnlyToAMaterialItsMuIsAlikeTo) {
  const IntruderScene scene = RubberMasoniteAndAnIntruder();
  const std::vector<MapPiece>& pieces = scene.pieces;
  const std::vector<int>& rubber = scene.rubber;
  const std::vector<int>& masonite = scene.masonite;
  const int intruder = scene.intruder;
  const SurfaceLevel level = Plate();
  for (const bool only_alike : {true, false}) {
    SCOPED_TRACE(only_alike ? "only to an alike material" : "to any (the build before)");
    RegionMapOptions options;
    options.move_only_to_alike_material = only_alike;
    auto map = RegionMap::Create(level, options);
    ASSERT_TRUE(map.ok()) << map.status();
    ASSERT_TRUE(map->SetPieces(pieces).ok());
    const auto& regions = map->regions();
    const int rubber_material = regions[map->piece_region()[rubber[0]]].material;
    const int masonite_material = regions[map->piece_region()[masonite[0]]].material;
    ASSERT_NE(rubber_material, masonite_material);
    EXPECT_EQ(map->pieces_moved_by_texture(), only_alike ? 0 : 1);
    EXPECT_EQ(regions[map->piece_region()[intruder]].material, only_alike ? masonite_material : rubber_material);
    absl::StatusOr<MapValue> value = map->ValueAtPosition(pieces[intruder].points.front() + Eigen::Vector3d(0, 8, 0));
    ASSERT_TRUE(value.ok()) << value.status();
    EXPECT_NEAR(value->mu, only_alike ? kMasoniteMu : kRubberMu, 0.02);
    // Either way it counts in neither material's mu.
    EXPECT_NEAR(regions[map->piece_region()[masonite[0]]].statistics.mu, PrecisionWeightedMu(pieces, masonite), 1e-12);
    EXPECT_NEAR(regions[map->piece_region()[rubber[0]]].statistics.mu, PrecisionWeightedMu(pieces, rubber), 1e-12);
  }
}

}  // namespace
}  // namespace surfmap
