#include "server/map/region_map.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include <gtest/gtest.h>
#include "server/map/testing/map_pieces.h"
#include "server/map/testing/paper_friction.h"

namespace surfmap {
namespace {

using testing::CrossingDrag;
using testing::MapOfPieces;
using testing::MasonitePiece;
using testing::Metric;
using testing::WoodPiece;
using testing::Plate;
using testing::StraightPiece;

// Glass as a drag may read it, a little above its 0.106.
constexpr double kGlassAsRead = 0.13;
using testing::kSandpaperMu;

// Glass drags along y at x = -30 and -20, sandpaper drags at x = 20 and 30.
std::vector<MapPiece> TwoHalves() {
  std::vector<MapPiece> pieces;
  int drag = 0;
  for (double x : {-30.0, -20.0}) pieces.push_back(StraightPiece(drag++, {x, -8, 0}, {x, 8, 0}, kGlassAsRead));
  for (double x : {20.0, 30.0}) pieces.push_back(StraightPiece(drag++, {x, -8, 0}, {x, 8, 0}, kSandpaperMu, 0.0, true));
  return pieces;
}

MapValue At(const RegionMap& map, const Eigen::Vector3d& p) {
  absl::StatusOr<MapValue> v = map.ValueAtPosition(p);
  EXPECT_TRUE(v.ok()) << v.status();
  return v.ok() ? *v : MapValue{};
}

TEST(RegionMapTest, AlikePiecesFormOneRegionEachWithThePooledMu) {
  const SurfaceLevel level = Plate();
  auto map = RegionMap::Create(level);
  ASSERT_TRUE(map.ok()) << map.status();
  ASSERT_TRUE(map->SetPieces(TwoHalves()).ok());
  ASSERT_EQ(map->regions().size(), 2u);
  EXPECT_EQ(map->piece_region(), (std::vector<int>{0, 0, 1, 1}));
  // Equal standard errors: the pooled mu is the plain mean, exactly.
  EXPECT_DOUBLE_EQ(map->regions()[0].statistics.mu, kGlassAsRead);
  EXPECT_DOUBLE_EQ(map->regions()[1].statistics.mu, kSandpaperMu);
  EXPECT_EQ(At(*map, {-40, 20, 0}).region, 0);
  EXPECT_DOUBLE_EQ(At(*map, {40, -20, 0}).mu, kSandpaperMu);
}

TEST(RegionMapTest, RegionsOfOneMaterialApartOnTheSurfaceShareTheirEstimates) {
  // Sandpaper at both ends of the plate, glass between: the two sandpaper
  // groups do not touch, so they are two regions, each with its own mu
  // (0.48 and 0.52, alike); as one material both report the pool, 0.50.
  std::vector<MapPiece> pieces;
  int drag = 0;
  for (double x : {-40.0, -35.0}) pieces.push_back(StraightPiece(drag++, {x, -8, 0}, {x, 8, 0}, 0.48, 0.0, true, 0.02));
  for (double x : {-10.0, 0.0, 10.0}) pieces.push_back(StraightPiece(drag++, {x, -8, 0}, {x, 8, 0}, kGlassAsRead));
  for (double x : {35.0, 40.0}) pieces.push_back(StraightPiece(drag++, {x, -8, 0}, {x, 8, 0}, 0.52, 0.0, true, 0.02));
  const SurfaceLevel level = Plate();
  RegionMapOptions separate;
  separate.pool_alike_regions = false;
  for (const bool pooled : {true, false}) {
    auto map = RegionMap::Create(level, pooled ? RegionMapOptions{} : separate);
    ASSERT_TRUE(map.ok());
    ASSERT_TRUE(map->SetPieces(pieces).ok());
    ASSERT_EQ(map->regions().size(), 3u);
    const TextureRegion& left = map->regions()[map->piece_region()[0]];
    const TextureRegion& right = map->regions()[map->piece_region()[5]];
    EXPECT_NEAR(left.own_statistics.mu, 0.48, 1e-12);
    EXPECT_NEAR(right.own_statistics.mu, 0.52, 1e-12);
    EXPECT_EQ(left.material == right.material, pooled);
    EXPECT_NEAR(At(*map, {-45, 0, 0}).mu, pooled ? 0.50 : 0.48, 1e-12) << pooled;
    EXPECT_NEAR(At(*map, {45, 0, 0}).mu, pooled ? 0.50 : 0.52, 1e-12) << pooled;
    // The pool's standard error: four pieces of se 0.02.
    if (pooled) {
      EXPECT_NEAR(left.statistics.mu_se, 0.01, 1e-12);
    }
    EXPECT_NE(map->regions()[map->piece_region()[3]].material, left.material);  // glass stays glass
  }
}

TEST(RegionMapTest, RoughnessComesOnlyFromPiecesThatHaveTheirOwnFit) {
  const SurfaceLevel level = Plate();
  auto map = RegionMap::Create(level);
  ASSERT_TRUE(map.ok());
  ASSERT_TRUE(map->SetPieces(TwoHalves()).ok());
  const MapValue glass = At(*map, {-25, 0, 0});
  EXPECT_FALSE(glass.has_roughness);
  const MapValue sand = At(*map, {25, 0, 0});
  ASSERT_TRUE(sand.has_roughness);
  ASSERT_EQ(sand.reflection.size(), 2u);
  EXPECT_DOUBLE_EQ(sand.reflection[0], 0.6);
  EXPECT_DOUBLE_EQ(sand.reflection[1], -0.25);
  EXPECT_NEAR(sand.sigma, 0.11, 1e-12);  // exp(median log sigma)
  // Per vertex: NaN where the region has no roughness.
  bool saw_nan = false;
  for (double s : map->log_sigma()) saw_nan |= std::isnan(s);
  EXPECT_TRUE(saw_nan);
}

// Glass at x < -20 (two drags); a patch read by three drags long enough for
// a roughness fit (0.36, se 0.02) with two 2 mm pieces at its rim without
// one (0.25, se 0.05). One drag per piece, numbered in order.
std::vector<MapPiece> PatchWithRimSlivers() {
  std::vector<MapPiece> pieces;
  int drag = 0;
  for (double x : {-30.0, -20.0}) pieces.push_back(StraightPiece(drag++, {x, -8, 0}, {x, 8, 0}, kGlassAsRead));
  for (double x : {20.0, 25.0, 30.0}) pieces.push_back(StraightPiece(drag++, {x, -8, 0}, {x, 8, 0}, 0.36, 0.0, true, 0.02));
  for (double x : {22.5, 27.5}) pieces.push_back(StraightPiece(drag++, {x, 8, 0}, {x, 10, 0}, 0.25, 0.0, false, 0.05));
  return pieces;
}

// Options the map refuses, with a message naming `field`.
void ExpectRefusedNaming(const SurfaceLevel& level, const RegionMapOptions& options, const std::string& field) {
  absl::StatusOr<RegionMap> refused = RegionMap::Create(level, options);
  ASSERT_FALSE(refused.ok()) << field;
  EXPECT_NE(refused.status().message().find(field), std::string::npos) << refused.status();
}

// Masonite-like drags at x < 0 and wood-like at x > 0 (map_pieces.h); with
// `wood_rough` false the wood drags have no roughness fit.
std::vector<MapPiece> AlikeFrictionsDifferentRoughness(bool wood_rough) {
  std::vector<MapPiece> pieces;
  int drag = 0;
  for (double x : {-30.0, -20.0}) pieces.push_back(MasonitePiece(drag++, {x, -8, 0}, {x, 8, 0}));
  for (double x : {20.0, 30.0}) {
    pieces.push_back(wood_rough ? WoodPiece(drag++, {x, -8, 0}, {x, 8, 0})
                                : StraightPiece(drag++, {x, -8, 0}, {x, 8, 0}, 0.42));
  }
  return pieces;
}

TEST(RegionMapTest, ConfusingTwoRegionsCostsTheirTextureDistanceInMuSquared) {
  const SurfaceLevel level = Plate();
  for (bool wood_rough : {true, false}) {
    absl::StatusOr<RegionMap> map = MapOfPieces(level, AlikeFrictionsDifferentRoughness(wood_rough));
    ASSERT_TRUE(map.ok()) << map.status();
    const int masonite = At(*map, {-25, 0, 0}).region, wood = At(*map, {25, 0, 0}).region;
    ASSERT_GE(masonite, 0);
    ASSERT_GE(wood, 0);
    ASSERT_NE(masonite, wood);
    const double jump2 = 0.06 * 0.06;
    EXPECT_NEAR(map->ConfusionCost(masonite, wood, Metric(TextureProperty::kFriction)), jump2, 1e-12);
    if (!wood_rough) {
      // Friction alone where one side has no roughness, whatever the property.
      EXPECT_NEAR(map->ConfusionCost(masonite, wood, Metric(TextureProperty::kBoth)), jump2, 1e-12);
      EXPECT_NEAR(map->ConfusionCost(masonite, wood, Metric(TextureProperty::kRoughness)), jump2, 1e-12);
      continue;
    }
    // The default metric (texture.h): mu / 0.05, k / 0.3, ln sigma / 0.5.
    const double rough2 =
        std::pow(0.10 / 0.3, 2) + std::pow(0.28 / 0.3, 2) + std::pow(std::log(0.16 / 0.06) / 0.5, 2);
    const double both = map->ConfusionCost(masonite, wood, Metric(TextureProperty::kBoth));
    EXPECT_NEAR(both, 0.05 * 0.05 * (std::pow(0.06 / 0.05, 2) + rough2), 1e-9);
    EXPECT_NEAR(map->ConfusionCost(masonite, wood, Metric(TextureProperty::kRoughness)), 0.05 * 0.05 * rough2, 1e-9);
    EXPECT_DOUBLE_EQ(both, map->ConfusionCost(wood, masonite, Metric(TextureProperty::kBoth)));
    EXPECT_GT(both, 4.0 * jump2);  // the roughness, not the friction, sets them apart
    EXPECT_EQ(map->ConfusionCost(masonite, masonite, Metric(TextureProperty::kBoth)), 0.0);
    EXPECT_EQ(map->ConfusionCost(-1, wood, Metric(TextureProperty::kBoth)), 0.0);
    // The job's metric, not a default: log sigma over 1.0 instead of 0.5.
    TextureDistanceOptions wider = Metric(TextureProperty::kBoth);
    wider.log_sigma_scale = 1.0;
    const double rough2_wider = rough2 - std::pow(std::log(0.16 / 0.06) / 0.5, 2) + std::pow(std::log(0.16 / 0.06), 2);
    EXPECT_NEAR(map->ConfusionCost(masonite, wood, wider), 0.05 * 0.05 * (std::pow(0.06 / 0.05, 2) + rough2_wider),
                1e-9);
    // Far from data: the pieces' spread in the metric. Two rough textures
    // two drags each: (n / (n - 1)) x the squared half-differences.
    const double friction = map->PriorTextureVariance(Metric(TextureProperty::kFriction));
    EXPECT_NEAR(friction, std::pow(map->prior_mu_std(), 2), 1e-15);
    EXPECT_NEAR(map->PriorTextureVariance(Metric(TextureProperty::kBoth)) - friction, 0.05 * 0.05 * rough2 / 3.0, 1e-9);
    EXPECT_NEAR(map->PriorTextureVariance(Metric(TextureProperty::kRoughness)), 0.05 * 0.05 * rough2 / 3.0, 1e-9);
  }
}

// Every region's mu is the precision-weighted mean, by the map's own
// per-piece statistics, of the pieces it names in mu_pieces: what lets a
// reader of the map (GetMap's MapRegion.pieces) check it.
void ExpectMuIsThePrecisionWeightedMeanOfItsMuPieces(const RegionMap& map) {
  ASSERT_EQ(map.piece_statistics().size(), map.pieces().size());
  for (const TextureRegion& region : map.regions()) {
    ASSERT_FALSE(region.mu_pieces.empty());
    double weight = 0.0, weighted_mu = 0.0;
    for (int i : region.mu_pieces) {
      const PieceStatistics& p = map.piece_statistics()[i];
      EXPECT_EQ(map.regions()[map.piece_region()[i]].material, region.material) << "piece " << i;
      weight += 1.0 / (p.mu_se * p.mu_se);
      weighted_mu += p.mu / (p.mu_se * p.mu_se);
    }
    EXPECT_NEAR(region.statistics.mu, weighted_mu / weight, 1e-12);
  }
}

TEST(RegionMapTest, AMaterialsMuComesFromItsLongPiecesWhenItHasEnoughOfThem) {
  // A patch read by three drags long enough for a roughness fit (0.36, se
  // 0.02) and two short pieces at its rim without one (0.25, se 0.05: alike
  // to the patch only for their large se, as a change's location error and
  // a wandering texture leave such pieces). Pooled by precision the two
  // would take the patch to 0.349; from its long pieces it reads 0.36.
  const std::vector<MapPiece> pieces = PatchWithRimSlivers();
  const double precision_pooled = (3 * 0.36 / (0.02 * 0.02) + 2 * 0.25 / (0.05 * 0.05)) / (3 / (0.02 * 0.02) + 2 / (0.05 * 0.05));
  const SurfaceLevel level = Plate();
  for (const int min_fitted : {3, 0, 4}) {
    RegionMapOptions options;
    options.min_fitted_pieces_for_mu = min_fitted;
    absl::StatusOr<RegionMap> map = MapOfPieces(level, pieces, options);
    ASSERT_TRUE(map.ok()) << map.status();
    const TextureRegion& patch = map->regions()[map->piece_region()[2]];
    ASSERT_EQ(map->regions()[map->piece_region()[5]].material, patch.material) << "the short pieces join the patch";
    // Four long pieces asked for and three present: every piece, as with 0.
    const double expected = min_fitted == 3 ? 0.36 : precision_pooled;
    EXPECT_NEAR(patch.statistics.mu, expected, 1e-12) << min_fitted;
    // The region names the pieces behind its mu: the three drags across the
    // patch, or those and the two slivers.
    std::vector<int> behind = patch.mu_pieces;
    std::sort(behind.begin(), behind.end());
    EXPECT_EQ(behind, min_fitted == 3 ? (std::vector<int>{2, 3, 4}) : (std::vector<int>{2, 3, 4, 5, 6})) << min_fitted;
    ExpectMuIsThePrecisionWeightedMeanOfItsMuPieces(*map);
    EXPECT_NEAR(At(*map, {25, 0, 0}).mu, expected, 1e-12) << min_fitted;
  }
  EXPECT_NEAR(precision_pooled, 0.3494, 1e-4);
  RegionMapOptions negative;
  negative.min_fitted_pieces_for_mu = -1;
  ExpectRefusedNaming(level, negative, "min_fitted_pieces_for_mu");
}

TEST(RegionMapTest, ACrossingTooShortToFitRoughnessStillCountsForMu) {
  // The patch above plus a 4.5 mm crossing without a roughness fit (0.38, se
  // 0.03), as a drag across a 6 mm strip leaves: at 4 mm and up a piece is
  // long enough for the material's mu (min_mu_piece_mm), the 2 mm rim
  // slivers are not. With 0 the rule is the roughness fit, as before.
  std::vector<MapPiece> pieces = PatchWithRimSlivers();
  const int drag = static_cast<int>(pieces.size());
  pieces.push_back(StraightPiece(drag, {27.5, -8, 0}, {27.5, -3.5, 0}, 0.38, 0.0, false, 0.03));
  const double with_crossing = (3 * 0.36 / (0.02 * 0.02) + 0.38 / (0.03 * 0.03)) / (3 / (0.02 * 0.02) + 1 / (0.03 * 0.03));
  const SurfaceLevel level = Plate();
  for (const double min_mm : {4.0, 0.0}) {
    RegionMapOptions options;
    options.min_mu_piece_mm = min_mm;
    absl::StatusOr<RegionMap> map = MapOfPieces(level, pieces, options);
    ASSERT_TRUE(map.ok()) << map.status();
    const TextureRegion& patch = map->regions()[map->piece_region()[2]];
    ASSERT_EQ(map->regions()[map->piece_region()[7]].material, patch.material) << "the crossing joins the patch";
    EXPECT_NEAR(patch.statistics.mu, min_mm > 0 ? with_crossing : 0.36, 1e-12) << min_mm;
  }
  EXPECT_NEAR(with_crossing, 0.3626, 1e-4);
  RegionMapOptions negative;
  negative.min_mu_piece_mm = -1.0;
  ExpectRefusedNaming(level, negative, "min_mu_piece_mm");
}

TEST(RegionMapTest, ADetectedChangePinsTheBoundaryWhereTheDragCrossedIt) {
  // Without a crossing the boundary lies midway between the data (x = 0);
  // a drag along x that changed at x = 8 puts it there.
  const SurfaceLevel level = Plate();
  auto map = RegionMap::Create(level);
  ASSERT_TRUE(map.ok());
  std::vector<MapPiece> pieces = TwoHalves();
  for (MapPiece& p : CrossingDrag(9, {0, 0, 0}, {8, 0, 0}, {16, 0, 0}, kGlassAsRead, kSandpaperMu)) pieces.push_back(p);
  ASSERT_TRUE(map->SetPieces(pieces).ok());
  ASSERT_EQ(map->regions().size(), 2u);
  ASSERT_EQ(map->change_marks().size(), 1u);
  EXPECT_NEAR((map->change_marks()[0].position - Eigen::Vector3d(8, 0, 0)).norm(), 0.0, 1e-9);
  // Within the near-data distance (the median edge, 2.5 mm) of the crossing.
  EXPECT_EQ(At(*map, {7.5, 0, 0}).region, 0);
  EXPECT_EQ(At(*map, {8.5, 0, 0}).region, 1);
}

TEST(RegionMapTest, AShortEndPieceAlikeToItsNeighbourMarksNoCrossing) {
  // The crossing at x = 8 above, and a drag in the sandpaper whose last
  // 1 mm reads 0.2 with a standard error of 0.2 (1.5 se from the sandpaper):
  // the map puts that sliver in glass, but it shows no crossing.
  const SurfaceLevel level = Plate();
  std::vector<MapPiece> pieces = TwoHalves();
  for (MapPiece& p : CrossingDrag(9, {0, 0, 0}, {8, 0, 0}, {16, 0, 0}, kGlassAsRead, kSandpaperMu)) pieces.push_back(p);
  std::vector<MapPiece> sliver = CrossingDrag(10, {16, 5, 0}, {23, 5, 0}, {24, 5, 0}, kSandpaperMu, 0.2);
  sliver[1].piece.mu_se = 0.2;
  for (MapPiece& p : sliver) pieces.push_back(p);
  RegionMapOptions every_change;
  every_change.min_end_piece_mark_mm = 0.0;  // the build before
  absl::StatusOr<RegionMap> before = MapOfPieces(level, pieces, every_change);
  ASSERT_TRUE(before.ok()) << before.status();
  ASSERT_EQ(before->change_marks().size(), 2u) << "the sliver, put in glass, is a crossing";
  absl::StatusOr<RegionMap> map = MapOfPieces(level, pieces);
  ASSERT_TRUE(map.ok()) << map.status();
  ASSERT_EQ(map->change_marks().size(), 1u);
  EXPECT_NEAR((map->change_marks()[0].position - Eigen::Vector3d(8, 0, 0)).norm(), 0.0, 1e-9);
  EXPECT_EQ(map->piece_region().size(), pieces.size()) << "the sliver's data stay in the map";
  // A sliver told apart from its neighbour (se 0.02: 15 se) is a crossing.
  pieces.back().piece.mu_se = 0.02;
  absl::StatusOr<RegionMap> told_apart = MapOfPieces(level, pieces);
  ASSERT_TRUE(told_apart.ok()) << told_apart.status();
  EXPECT_EQ(told_apart->change_marks().size(), 2u);
  RegionMapOptions negative;
  negative.end_piece_mark_z = -1.0;
  ExpectRefusedNaming(level, negative, "end_piece_mark_z");
}

TEST(RegionMapTest, AShortEndPieceAlikeToItsNeighbourRefusesNoBoundary) {
  // A sandpaper dot of radius 7 mm in glass, crossed by three drags (at 10,
  // 130 and 250 degrees round it), is drawn as a circle (boundary_dots.h).
  // A fourth drag comes in at 190 degrees and stops 1 mm short of the dot;
  // its last 1 mm reads 0.45 +- 0.2, too short and too like the glass to
  // mark a crossing, and the map does not put it with the glass. It lies
  // 1-2 mm outside the circle, so it used to refuse it (the build before),
  // and the map went round the rim by the nearest data alone.
  const SurfaceLevel level = Plate();
  const Eigen::Vector3d centre(10, 0, 0);
  constexpr double kRadius = 7.0;
  auto at = [&](double r, double deg) {
    const double a = deg * std::numbers::pi / 180.0;
    return Eigen::Vector3d(centre + r * Eigen::Vector3d(std::cos(a), std::sin(a), 0.0));
  };
  std::vector<MapPiece> pieces;
  int drag = 0;
  for (double x : {-40.0, -30.0}) pieces.push_back(StraightPiece(drag++, {x, -8, 0}, {x, 8, 0}, kGlassAsRead));
  for (double deg : {10.0, 130.0, 250.0}) {
    for (MapPiece& p : CrossingDrag(drag++, at(15, deg), at(kRadius, deg), at(1, deg), kGlassAsRead, kSandpaperMu)) {
      pieces.push_back(p);
    }
  }
  std::vector<MapPiece> stub = CrossingDrag(drag++, at(20, 190), at(9, 190), at(8, 190), kGlassAsRead, 0.45);
  stub[1].piece.mu_se = 0.2;
  for (MapPiece& p : stub) pieces.push_back(p);
  // The rim, 1.5 mm either side of the circle, every 10 degrees, but for
  // the outer point at 190 degrees: the stub's own data lie there, and they
  // stay in the map.
  auto right_round_the_rim = [&](const RegionMap& map) {
    int right = 0;
    for (int deg = 0; deg < 360; deg += 10) {
      right += At(map, at(kRadius - 1.5, deg)).mu > 0.4;
      if (deg != 190) right += At(map, at(kRadius + 1.5, deg)).mu < 0.2;
    }
    return right;
  };
  RegionMapOptions before;
  before.boundaries_ignore_unconfirmed_end_pieces = false;
  for (const bool ignore : {false, true}) {
    absl::StatusOr<RegionMap> map = MapOfPieces(level, pieces, ignore ? RegionMapOptions{} : before);
    ASSERT_TRUE(map.ok()) << map.status();
    ASSERT_EQ(map->change_marks().size(), 3u) << "the stub marks no crossing";
    const std::vector<int>& region = map->piece_region();
    ASSERT_NE(map->regions()[region.back()].material, map->regions()[region[0]].material)
        << "the stub's end is not put with the glass";
    if (ignore) {
      EXPECT_EQ(right_round_the_rim(*map), 71) << "the circle is drawn";
    } else {
      EXPECT_LT(right_round_the_rim(*map), 71) << "the circle was refused (64 of 71 when written)";
    }
  }
}

// Glass at x < 0, sandpaper at x > 0, crossed by drags at y = -8, 0 and 8.
// The middle drag's detector put two changes round the step, half_mm either
// side of it: a piece reading 0.30 +- 0.05, between the two, that the map
// puts with a rubber piece far off. *transition: that piece's index;
// *blended_drag: its drag.
std::vector<MapPiece> PiecesWithABlendedCrossing(double half_mm, int* transition, int* blended_drag) {
  std::vector<MapPiece> pieces;
  int drag = 0;
  pieces.push_back(StraightPiece(drag++, {-45, -20, 0}, {-30, -20, 0}, 0.30));
  for (double y : {-8.0, 8.0}) {
    for (MapPiece& p : CrossingDrag(drag++, {-12, y, 0}, {0, y, 0}, {12, y, 0}, kGlassAsRead, kSandpaperMu)) {
      pieces.push_back(p);
    }
  }
  *blended_drag = drag++;
  std::vector<MapPiece> blended =
      CrossingDrag(*blended_drag, {-12, 0, 0}, {-half_mm, 0, 0}, {12, 0, 0}, kGlassAsRead, kSandpaperMu);
  MapPiece t = StraightPiece(*blended_drag, {-half_mm, 0, 0}, {half_mm, 0, 0}, 0.30, blended[0].piece.end_mm);
  t.piece.starts_at_change = t.piece.ends_at_change = true;
  t.piece.mu_se = 0.05;
  blended[1] = StraightPiece(*blended_drag, {half_mm, 0, 0}, {12, 0, 0}, kSandpaperMu, t.piece.end_mm);
  blended[1].piece.starts_at_change = true;
  pieces.insert(pieces.end(), {blended[0], t, blended[1]});
  *transition = static_cast<int>(pieces.size()) - 2;
  return pieces;
}

// The map of PiecesWithABlendedCrossing: with one_crossing, the blended
// drag crossed from glass to sandpaper in the transition's middle and the
// boundary runs straight through all three crossings; without, glass to
// rubber and rubber to sandpaper, and the rubber's data refuse the link
// between the other two drags' crossings.
void ExpectTheBlendedCrossing(const RegionMapOptions& options, double half_mm, bool one_crossing) {
  const SurfaceLevel level = Plate();
  int t = -1, blended_drag = -1;
  const std::vector<MapPiece> pieces = PiecesWithABlendedCrossing(half_mm, &t, &blended_drag);
  absl::StatusOr<RegionMap> map = MapOfPieces(level, pieces, options);
  ASSERT_TRUE(map.ok()) << map.status();
  const std::vector<int>& region = map->piece_region();
  const int glass = map->regions()[region[1]].material, sandpaper = map->regions()[region[2]].material;
  const int rubber = map->regions()[region[0]].material;
  ASSERT_EQ(map->regions()[region[t]].material, rubber) << "the transition is put with the rubber";
  ASSERT_NE(rubber, glass);
  ASSERT_NE(rubber, sandpaper);
  int glass_to_sandpaper = 0;
  for (const ChangeMark& m : map->change_marks()) {
    if (m.before != glass || m.after != sandpaper) continue;
    ++glass_to_sandpaper;
    if (m.drag == blended_drag) {
      EXPECT_NEAR(m.position.x(), 0.0, 0.1) << "the transition's middle";
    }
  }
  if (one_crossing) {
    EXPECT_EQ(map->change_marks().size(), 3u);
    EXPECT_EQ(glass_to_sandpaper, 3);
    EXPECT_GE(map->boundary_links(), 1);
    for (double y : {-4.0, 4.0}) {
      EXPECT_EQ(map->regions()[At(*map, {-0.5, y, 0}).region].material, glass) << y;
      EXPECT_EQ(map->regions()[At(*map, {0.5, y, 0}).region].material, sandpaper) << y;
    }
  } else {
    EXPECT_EQ(map->change_marks().size(), 4u);
    EXPECT_EQ(glass_to_sandpaper, 2);
    EXPECT_EQ(map->boundary_links(), 0);
  }
}

TEST(RegionMapTest, APieceThatBlendsItsNeighboursMarksOneCrossingInItsMiddle) {
  // A 1.2 mm transition.
  RegionMapOptions before;
  before.transition_pieces_mark_one_crossing = false;
  {
    SCOPED_TRACE("the build before");
    ExpectTheBlendedCrossing(before, 0.6, /*one_crossing=*/false);
  }
  {
    SCOPED_TRACE("one crossing");
    ExpectTheBlendedCrossing(RegionMapOptions{}, 0.6, /*one_crossing=*/true);
  }
}

TEST(RegionMapTest, ATransitionMayBeTwoMillimetresLong) {
  // The bottle (seed 4): a 1.8 mm piece between glass and sandpaper, put in
  // a material of its own. Longer than max_transition_piece_mm it still
  // marks two crossings, and the link beside it is refused.
  RegionMapOptions before;
  before.max_transition_piece_mm = 1.5;
  {
    SCOPED_TRACE("1.5 mm, the build before");
    ExpectTheBlendedCrossing(before, 1.0, /*one_crossing=*/false);
  }
  {
    SCOPED_TRACE("the default");
    ExpectTheBlendedCrossing(RegionMapOptions{}, 1.0, /*one_crossing=*/true);
  }
  {
    SCOPED_TRACE("3 mm is no transition");
    ExpectTheBlendedCrossing(RegionMapOptions{}, 1.5, /*one_crossing=*/false);
  }
}

TEST(RegionMapTest, ATransitionsLengthIsValidated) {
  for (const double length : {-1.0, std::numeric_limits<double>::quiet_NaN()}) {
    RegionMapOptions bad;
    bad.max_transition_piece_mm = length;
    std::string why;
    EXPECT_FALSE(bad.IsValid(&why)) << length;
    EXPECT_NE(why.find("max_transition_piece_mm"), std::string::npos) << why;
    const absl::StatusOr<RegionMap> map = RegionMap::Create(Plate(), bad);
    EXPECT_EQ(map.status().code(), absl::StatusCode::kInvalidArgument) << length;
  }
}

TEST(RegionMapTest, CrossingsIntoTwoStretchesOfOneMaterialAreLinked) {
  // Glass at x < 0, sandpaper at x > 0: drags cross the boundary at y = -8
  // and y = 8, and a rubber piece at y = 0 keeps the two sandpaper pieces
  // from touching, so they are two regions of one material. Their crossings
  // are crossings of one boundary.
  std::vector<MapPiece> pieces;
  int drag = 0;
  for (double x : {-30.0, -20.0}) pieces.push_back(StraightPiece(drag++, {x, -8, 0}, {x, 8, 0}, kGlassAsRead));
  for (double y : {-8.0, 8.0}) {
    for (MapPiece& p : CrossingDrag(drag++, {-8, y, 0}, {0, y, 0}, {8, y, 0}, kGlassAsRead, kSandpaperMu)) {
      pieces.push_back(p);
    }
  }
  pieces.push_back(StraightPiece(drag++, {4, 0, 0}, {12, 0, 0}, 0.3));
  const SurfaceLevel level = Plate();
  RegionMapOptions by_region;
  by_region.link_materials = false;
  for (const bool materials : {true, false}) {
    auto map = RegionMap::Create(level, materials ? RegionMapOptions{} : by_region);
    ASSERT_TRUE(map.ok());
    ASSERT_TRUE(map->SetPieces(pieces).ok());
    const std::vector<int>& region = map->piece_region();
    const int first = region[3], second = region[5];  // the two sandpaper pieces
    ASSERT_NE(first, second);
    ASSERT_EQ(map->regions()[first].material, map->regions()[second].material);
    EXPECT_EQ(map->boundary_links(), materials ? 1 : 0) << (materials ? "by material" : "by region");
    if (materials) {
      // The link's points on the sandpaper side belong to the stretch nearer them.
      EXPECT_EQ(At(*map, {0.5, -6, 0}).region, first);
      EXPECT_EQ(At(*map, {0.5, 6, 0}).region, second);
      EXPECT_NEAR(At(*map, {-0.5, 0, 0}).mu, kGlassAsRead, 1e-9);
    }
  }
}

TEST(RegionMapTest, UncertaintyIsTheStandardErrorAtDataAndRisesAwayFromIt) {
  const SurfaceLevel level = Plate();
  auto map = RegionMap::Create(level);
  ASSERT_TRUE(map.ok());
  ASSERT_TRUE(map->SetPieces(TwoHalves()).ok());
  // At a data point only the region mean's standard error remains: two
  // pieces of se 0.002 pool to 0.002 / sqrt(2).
  const double se = map->regions()[0].statistics.mu_se;
  EXPECT_NEAR(se, 0.002 / std::sqrt(2.0), 1e-9);
  // Vertex 418 is (-30, 0), on a glass drag (41 vertices per row).
  ASSERT_EQ(level.limit_positions[418], Eigen::Vector3d(-30, 0, 0));
  const double at_data = map->mu_std()[418];
  const double far = At(*map, {-48, 23, 0}).mu_std;
  const double at_boundary = At(*map, {0, 0, 0}).mu_std;
  // The random walker leaves the other region a probability ~1e-4 even on a
  // data vertex, so the boundary term is not exactly 0 there: small.
  EXPECT_GE(at_data, se);
  EXPECT_LT(at_data, 0.005) << "far " << far << " boundary " << at_boundary;
  EXPECT_GT(far, 5.0 * at_data);
  // Midway between glass and sandpaper data the boundary term dominates:
  // p (1 - p) jump^2 with p ~ 1/2 gives ~ jump / 2 = 0.185.
  EXPECT_GT(at_boundary, 0.1);
  EXPECT_GT(at_boundary, far);
}

TEST(RegionMapTest, BadPiecesAreRefusedByNameAndTheMapKeepsItsState) {
  const SurfaceLevel level = Plate();
  auto map = RegionMap::Create(level);
  ASSERT_TRUE(map.ok());
  EXPECT_EQ(map->SetPieces({}).code(), absl::StatusCode::kInvalidArgument);
  ASSERT_TRUE(map->SetPieces(TwoHalves()).ok());
  std::vector<MapPiece> bad = TwoHalves();
  bad[2].points[1] = Eigen::Vector3d(std::nan(""), 0, 0);
  const absl::Status s = map->SetPieces(bad);
  EXPECT_EQ(s.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(s.message().find("map piece 2: point 1 is not finite"), std::string::npos) << s;
  bad = TwoHalves();
  bad[1].points.clear();
  EXPECT_NE(map->SetPieces(bad).message().find("map piece 1: has no points"), std::string::npos);
  EXPECT_EQ(map->regions().size(), 2u);
  EXPECT_EQ(map->pieces().size(), 4u);
  EXPECT_DOUBLE_EQ(At(*map, {40, 0, 0}).mu, kSandpaperMu);
}

TEST(RegionMapTest, ANegativeOrUndefinedSpreadFloorIsRefusedByName) {
  const SurfaceLevel level = Plate();
  for (double floor : {-0.01, std::nan("")}) {
    RegionMapOptions options;
    options.merge.spread_floor = floor;
    const absl::StatusOr<RegionMap> map = RegionMap::Create(level, options);
    EXPECT_EQ(map.status().code(), absl::StatusCode::kInvalidArgument) << floor;
    EXPECT_NE(map.status().message().find("merge: spread_floor"), std::string::npos) << map.status();
  }
  RegionMapOptions off;
  off.merge.spread_floor = 0.0;  // the plan's map: spreads compared however small
  EXPECT_TRUE(RegionMap::Create(level, off).ok());
}

TEST(RegionMapTest, BadLinkOptionsAreRefusedByName) {
  const SurfaceLevel level = Plate();
  // A zero seed spacing would ask for infinitely many link points; a NaN
  // limit would compare false and let every crossing through.
  struct Case {
    void (*set)(BoundaryLinkOptions&);
    const char* name;
  };
  const Case cases[] = {
      {[](BoundaryLinkOptions& o) { o.seed_spacing_mm = 0.0; }, "links: seed_spacing_mm"},
      {[](BoundaryLinkOptions& o) { o.corridor_mm = -1.0; }, "links: corridor_mm"},
      {[](BoundaryLinkOptions& o) { o.min_extension_crossing_cos = std::nan(""); }, "links: min_extension_crossing_cos"},
      {[](BoundaryLinkOptions& o) { o.max_extension_turn_deg = 200.0; }, "links: max_extension_turn_deg"},
      {[](BoundaryLinkOptions& o) { o.min_crossing_cos = 1.5; }, "links: min_crossing_cos"},
      {[](BoundaryLinkOptions& o) { o.max_line_turn_deg = -1.0; }, "links: max_line_turn_deg"},
      {[](BoundaryLinkOptions& o) { o.max_line_crossing_deg = 95.0; }, "links: max_line_crossing_deg"},
      {[](BoundaryLinkOptions& o) { o.max_dot_radius_mm = std::nan(""); }, "links: max_dot_radius_mm"},
      {[](BoundaryLinkOptions& o) { o.max_dot_chord_mm = 0.0; }, "links: max_dot_chord_mm"},
      {[](BoundaryLinkOptions& o) { o.max_dot_data_offset_mm = -0.1; }, "links: max_dot_data_offset_mm"},
      {[](BoundaryLinkOptions& o) { o.max_corner_side_residual_mm = -0.5; }, "links: max_corner_side_residual_mm"},
  };
  for (const Case& c : cases) {
    RegionMapOptions options;
    c.set(options.links);
    const absl::StatusOr<RegionMap> map = RegionMap::Create(level, options);
    EXPECT_EQ(map.status().code(), absl::StatusCode::kInvalidArgument) << c.name;
    EXPECT_NE(map.status().message().find(c.name), std::string::npos) << map.status();
  }
  RegionMapOptions off;
  off.links.max_extension_turn_deg = 0.0;  // off is valid
  off.links.corner_reach_mm = 0.0;
  off.links.max_line_turn_deg = 0.0;
  off.links.max_dot_radius_mm = 0.0;
  off.links.max_corner_side_residual_mm = 0.0;
  EXPECT_TRUE(RegionMap::Create(level, off).ok());
}

}  // namespace
}  // namespace surfmap
