#include "server/plan/boundary_selection.h"

#include <cmath>
#include <vector>

#include <Eigen/Geometry>
#include <gtest/gtest.h>
#include "server/map/testing/map_pieces.h"

namespace surfmap {
namespace {

constexpr double kDragLengthMm = 20.0;

// Glass drags along y at x = -30 and -20, sandpaper at x = 20 and 30: the
// boundary somewhere in x in (-20, 20), pinned nowhere.
absl::StatusOr<RegionMap> UnpinnedBoundary(const SurfaceLevel& level) {
  std::vector<MapPiece> pieces;
  int drag = 0;
  for (double x : {-30.0, -20.0}) pieces.push_back(testing::StraightPiece(drag++, {x, -20, 0}, {x, 20, 0}, 0.13));
  for (double x : {20.0, 30.0}) pieces.push_back(testing::StraightPiece(drag++, {x, -20, 0}, {x, 20, 0}, 0.5));
  return testing::MapOfPieces(level, pieces);
}

TEST(BoundarySelectorTest, TheBestDragGoesAcrossTheUnpinnedBoundaryBetweenTheData) {
  const SurfaceLevel level = testing::Plate();
  auto map = UnpinnedBoundary(level);
  ASSERT_TRUE(map.ok()) << map.status();
  const BoundarySelector selector(level, kDragLengthMm);
  const std::vector<char> every(level.limit_positions.size(), 1);
  const BoundarySelection best = selector.Select(*map, every, {});
  ASSERT_GE(best.vertex, 0);
  EXPECT_EQ(best.directed, -1);
  EXPECT_LT(std::abs(level.limit_positions[best.vertex].x()), 10.0);
  EXPECT_GT(std::abs(best.direction.x()), std::cos(M_PI / 6.0)) << "not across the boundary (x = const)";
  // Part of its gain is the boundary's (the gap is 40 mm wide, so the
  // far-from-data term holds the rest: 0.40 measured).
  EXPECT_GT(best.boundary_share, 0.2);
}

TEST(BoundarySelectorTest, ADirectedDragWinsWithItsExtraGainAndKeepsItsDirection) {
  const SurfaceLevel level = testing::Plate();
  auto map = UnpinnedBoundary(level);
  ASSERT_TRUE(map.ok());
  const BoundarySelector selector(level, kDragLengthMm);
  const std::vector<char> every(level.limit_positions.size(), 1);
  const BoundarySelection map_only = selector.Select(*map, every, {});
  // Vertex 418 is (-30, 0): on glass data, where the map alone gains little.
  const std::vector<DirectedCandidate> directed = {{418, Eigen::Vector3d::UnitY(), 10.0 * map_only.gain}};
  const BoundarySelection best = selector.Select(*map, every, {}, directed);
  EXPECT_EQ(best.directed, 0);
  EXPECT_EQ(best.vertex, 418);
  EXPECT_EQ(best.direction, Eigen::Vector3d::UnitY());
  EXPECT_GT(best.gain, 10.0 * map_only.gain);
  // Without enough extra gain the map's own choice stands.
  const std::vector<DirectedCandidate> weak = {{418, Eigen::Vector3d::UnitY(), 0.0}};
  EXPECT_EQ(selector.Select(*map, every, {}, weak).vertex, map_only.vertex);
}

// Glass drags (mu 0.13, too smooth for roughness) at x = -45, -40; masonite
// (0.36, sigma 0.16) at -15, -10; wood (0.42, sigma 0.06) at 20, 25: a
// boundary of a large friction jump in x in (-40, -15) and one of alike
// frictions but different roughness in (-10, 20).
absl::StatusOr<RegionMap> GlassMasoniteWood(const SurfaceLevel& level) {
  std::vector<MapPiece> pieces;
  int drag = 0;
  for (double x : {-45.0, -40.0}) pieces.push_back(testing::StraightPiece(drag++, {x, -20, 0}, {x, 20, 0}, 0.13));
  for (double x : {-15.0, -10.0}) pieces.push_back(testing::MasonitePiece(drag++, {x, -20, 0}, {x, 20, 0}));
  for (double x : {20.0, 25.0}) pieces.push_back(testing::WoodPiece(drag++, {x, -20, 0}, {x, 20, 0}));
  return testing::MapOfPieces(level, pieces);
}

// Weighed by texture distance (a job of property both), the alike-friction
// boundary gains on the large-jump one by the ratio of their confusion
// costs to their mu jumps squared.
TEST(BoundarySelectorTest, TextureCostWeighsABoundaryByItsRoughnessToo) {
  const SurfaceLevel level = testing::Plate();
  absl::StatusOr<RegionMap> map = GlassMasoniteWood(level);
  ASSERT_TRUE(map.ok()) << map.status();
  const BoundarySelector friction(level, kDragLengthMm), texture(level, kDragLengthMm, testing::Metric(TextureProperty::kBoth));
  const int jump_gap = friction.NearestVertex({-27.5, 0, 0}, 5.0), rough_gap = friction.NearestVertex({5, 0, 0}, 5.0);
  ASSERT_TRUE(jump_gap >= 0 && rough_gap >= 0);
  const auto boundary_gain = [&](const BoundarySelector& s, int v) {
    const BoundarySelection b = s.BestDirection(*map, v, {});
    EXPECT_GT(std::abs(b.direction.x()), std::cos(M_PI / 6.0)) << "not across the boundary";
    return b.gain * b.boundary_share;
  };
  const auto far_gain = [&](const BoundarySelector& s, int v) {
    const BoundarySelection b = s.BestDirection(*map, v, {});
    return b.gain * (1.0 - b.boundary_share);
  };
  const double f_jump = boundary_gain(friction, jump_gap), f_rough = boundary_gain(friction, rough_gap);
  const double t_jump = boundary_gain(texture, jump_gap), t_rough = boundary_gain(texture, rough_gap);
  ASSERT_TRUE(f_jump > 0.0 && f_rough > 0.0 && t_jump > 0.0 && t_rough > 0.0);
  const auto region_at = [&](double x) { return map->ValueAtPosition({x, 0, 0})->region; };
  const int glass = region_at(-42.5), masonite = region_at(-12.5), wood = region_at(22.5);
  const double jump_ratio = map->ConfusionCost(glass, masonite, testing::Metric(TextureProperty::kBoth)) / std::pow(0.23, 2);
  const double rough_ratio = map->ConfusionCost(masonite, wood, testing::Metric(TextureProperty::kBoth)) / std::pow(0.06, 2);
  EXPECT_NEAR(jump_ratio, 1.0, 1e-9);  // glass has no roughness: friction alone tells it apart
  ASSERT_GT(rough_ratio, 4.0);
  // Nearly every vertex near each gap's middle lies between its own two
  // regions (a few between glass and wood: 5 %).
  EXPECT_NEAR((t_rough / t_jump) / (f_rough / f_jump), rough_ratio / jump_ratio, 0.05 * rough_ratio);
  // Far from data the surface may differ by the pieces' spread in the same metric.
  const double far_ratio =
      map->PriorTextureVariance(testing::Metric(TextureProperty::kBoth)) / map->PriorTextureVariance(testing::Metric(TextureProperty::kFriction));
  EXPECT_GT(far_ratio, 1.0);
  EXPECT_NEAR(far_gain(texture, rough_gap) / far_gain(friction, rough_gap), far_ratio, 1e-6 * far_ratio);
}

// A misclassification cost c adds c to the squared jump of each boundary
// between two materials: the low-contrast boundary (masonite | wood, 0.06
// apart) gains on the glass one (0.23) by the ratio of (jump^2 + c) to
// jump^2. The far-from-data term grows by the boundaries' total growth, the
// same factor everywhere, so exploring keeps its share. c = 0 is the squared
// error alone, to the bit.
TEST(BoundarySelectorTest, AMisclassificationCostLiftsALowContrastBoundary) {
  const SurfaceLevel level = testing::Plate();
  absl::StatusOr<RegionMap> map = GlassMasoniteWood(level);
  ASSERT_TRUE(map.ok()) << map.status();
  constexpr double kCost = 0.03;
  const BoundarySelector squared(level, kDragLengthMm), zero(level, kDragLengthMm, BoundarySelector::Friction(), 0.0),
      priced(level, kDragLengthMm, BoundarySelector::Friction(), kCost);
  const int jump_gap = squared.NearestVertex({-27.5, 0, 0}, 5.0), rough_gap = squared.NearestVertex({5, 0, 0}, 5.0);
  ASSERT_TRUE(jump_gap >= 0 && rough_gap >= 0);
  const std::vector<char> every(level.limit_positions.size(), 1);
  const BoundarySelection a = squared.Select(*map, every, {}), b = zero.Select(*map, every, {});
  EXPECT_EQ(a.vertex, b.vertex);
  EXPECT_EQ(a.gain, b.gain);
  EXPECT_EQ(a.direction, b.direction);
  const auto parts = [&](const BoundarySelector& s, int v) {
    const BoundarySelection x = s.BestDirection(*map, v, {});
    return std::pair<double, double>{x.gain * x.boundary_share, x.gain * (1.0 - x.boundary_share)};
  };
  const auto [jump0, jump_far0] = parts(squared, jump_gap);
  const auto [rough0, rough_far0] = parts(squared, rough_gap);
  const auto [jump1, jump_far1] = parts(priced, jump_gap);
  const auto [rough1, rough_far1] = parts(priced, rough_gap);
  ASSERT_TRUE(jump0 > 0.0 && rough0 > 0.0);
  const double jump2 = std::pow(0.23, 2), rough2 = std::pow(0.06, 2);
  // Nearly every vertex near each gap's middle lies between its own two
  // regions (a few between glass and wood): 5 %.
  EXPECT_NEAR(jump1 / jump0, (jump2 + kCost) / jump2, 0.05 * (jump2 + kCost) / jump2);
  EXPECT_NEAR(rough1 / rough0, (rough2 + kCost) / rough2, 0.05 * (rough2 + kCost) / rough2);
  EXPECT_GT(rough1 / jump1, 5.0 * rough0 / jump0);
  const double far_growth = rough_far1 / rough_far0;
  EXPECT_NEAR(jump_far1 / jump_far0, far_growth, 1e-9 * far_growth);
  // Between the two boundaries' growths: the total is theirs (and the few
  // vertices between glass and wood), weighed by their squared errors.
  EXPECT_GT(far_growth, (jump2 + kCost) / jump2);
  EXPECT_LT(far_growth, (rough2 + kCost) / rough2);
}

TEST(SmallMaterialWeightTest, IsTheMeanMaterialsAreaOverTheSmallerSidesClamped) {
  EXPECT_DOUBLE_EQ(SmallMaterialWeight(100.0, 300.0, 4.0), 3.0);
  EXPECT_DOUBLE_EQ(SmallMaterialWeight(50.0, 300.0, 4.0), 4.0);
  EXPECT_DOUBLE_EQ(SmallMaterialWeight(600.0, 300.0, 4.0), 1.0) << "a large material weighs no less";
  EXPECT_DOUBLE_EQ(SmallMaterialWeight(0.0, 300.0, 4.0), 4.0) << "no area yet";
  EXPECT_DOUBLE_EQ(SmallMaterialWeight(100.0, 300.0, 1.0), 1.0);
}

// Each material's area on the map (a third of each triangle to each of its
// vertices, every vertex to its region's material).
std::vector<double> MaterialAreas(const SurfaceLevel& level, const RegionMap& map) {
  std::vector<double> area(map.regions().size(), 0.0);
  const auto& x = level.limit_positions;
  for (const auto& t : level.triangles) {
    const double third = 0.5 * (x[t[1]] - x[t[0]]).cross(x[t[2]] - x[t[0]]).norm() / 3.0;
    for (int v : t) {
      const int r = map.region()[v];
      if (r >= 0 && map.regions()[r].material >= 0) area[map.regions()[r].material] += third;
    }
  }
  std::erase_if(area, [](double a) { return a <= 0.0; });
  return area;
}

// Weighed by the smaller material, each boundary's misclassification part
// grows by SmallMaterialWeight of its sides' areas: the boundary gain at
// each gap grows by 1 + share * (w - 1), share the part c had of it
// (c / (jump^2 + c)). 5 %: a few vertices near each gap lie between glass
// and wood. With weight 1 the plan is the build before's, to the bit.
TEST(BoundarySelectorTest, ASmallMaterialsBoundaryWeighsByItsArea) {
  const SurfaceLevel level = testing::Plate();
  absl::StatusOr<RegionMap> map = GlassMasoniteWood(level);
  ASSERT_TRUE(map.ok()) << map.status();
  constexpr double kCost = 0.03, kMaxWeight = 4.0;
  const BoundarySelector alike(level, kDragLengthMm, BoundarySelector::Friction(), kCost),
      one(level, kDragLengthMm, BoundarySelector::Friction(), kCost, false, 1.0),
      weighed(level, kDragLengthMm, BoundarySelector::Friction(), kCost, false, kMaxWeight);
  const std::vector<char> every(level.limit_positions.size(), 1);
  const BoundarySelection a = alike.Select(*map, every, {}), b = one.Select(*map, every, {});
  EXPECT_EQ(a.vertex, b.vertex);
  EXPECT_EQ(a.gain, b.gain);
  // Materials in order of first region: glass, masonite, wood.
  const std::vector<double> area = MaterialAreas(level, *map);
  ASSERT_EQ(area.size(), 3u);
  const double mean = (area[0] + area[1] + area[2]) / 3.0;
  const int glass_side = alike.NearestVertex({-27.5, 0, 0}, 5.0), wood_side = alike.NearestVertex({5, 0, 0}, 5.0);
  ASSERT_TRUE(glass_side >= 0 && wood_side >= 0);
  const auto boundary_gain = [&](const BoundarySelector& s, int v) {
    const BoundarySelection x = s.BestDirection(*map, v, {});
    return x.gain * x.boundary_share;
  };
  const auto expected_growth = [&](double jump, double smaller_area) {
    const double share = kCost / (jump * jump + kCost);
    return 1.0 + share * (SmallMaterialWeight(smaller_area, mean, kMaxWeight) - 1.0);
  };
  const double glass_growth = boundary_gain(weighed, glass_side) / boundary_gain(alike, glass_side);
  const double wood_growth = boundary_gain(weighed, wood_side) / boundary_gain(alike, wood_side);
  const double glass_expected = expected_growth(0.23, std::min(area[0], area[1]));
  const double wood_expected = expected_growth(0.06, std::min(area[1], area[2]));
  EXPECT_GT(glass_expected, 1.05) << "the test's map has a material smaller than the mean";
  EXPECT_NEAR(glass_growth, glass_expected, 0.05 * glass_expected);
  EXPECT_NEAR(wood_growth, wood_expected, 0.05 * wood_expected);
}

// Glass drags along y at x = -30 and -20: one material, so a drag gains
// only far from data. On the plate (2.5 mm grid) the map's correlation
// length is a tenth of its diagonal, 10.9 mm.
absl::StatusOr<RegionMap> TwoGlassDrags(const SurfaceLevel& level) {
  std::vector<MapPiece> pieces;
  int drag = 0;
  for (double x : {-30.0, -20.0}) pieces.push_back(testing::StraightPiece(drag++, {x, -20, 0}, {x, 20, 0}, 0.13));
  return testing::MapOfPieces(level, pieces);
}

// A drag along y 40 mm from data brings its whole corridor nearer: a vertex
// t mm off its path keeps exp(-t / l) of its far variance removable (l, half
// the correlation length, 5.45 mm), 0.61 over the corridor's columns t = 0,
// 2.5 and 5 mm. Between the two drags every vertex already lies within 5 mm
// of data, and a drag down the middle brings only the vertices within 2.5 mm
// of its path nearer: 0.37 of what the build before counted, measured.
TEST(BoundarySelectorTest, AFarGainExpectedCountsOnlyWhatBringingDataNearerTakesOff) {
  const SurfaceLevel level = testing::Plate();
  absl::StatusOr<RegionMap> map = TwoGlassDrags(level);
  ASSERT_TRUE(map.ok()) << map.status();
  const BoundarySelector in_full(level, kDragLengthMm),
      expected(level, kDragLengthMm, BoundarySelector::Friction(), 0.0, false, 1.0, /*far_gain_expected=*/true);
  const int between = in_full.NearestVertex({-25, 0, 0}, 1.0), open = in_full.NearestVertex({20, 0, 0}, 1.0);
  ASSERT_TRUE(between >= 0 && open >= 0);
  // A drag along y there: the only candidate.
  const std::vector<char> none(level.limit_positions.size(), 0);
  const auto gain = [&](const BoundarySelector& s, int v) {
    const std::vector<DirectedCandidate> along_y = {{v, Eigen::Vector3d::UnitY(), 0.0}};
    return s.Select(*map, none, {}, along_y).gain;
  };
  const double between_share = gain(expected, between) / gain(in_full, between);
  const double open_share = gain(expected, open) / gain(in_full, open);
  EXPECT_GT(open_share, 0.5);
  EXPECT_LT(open_share, 0.75);
  EXPECT_GT(between_share, 0.0) << "the middle band is brought nearer";
  EXPECT_LT(between_share, 0.7 * open_share);
}

// A coverage drag between two drags 10 mm apart: down the middle of the gap
// it brings a 10 mm band nearer data; across them, only the two short
// stretches between and beyond them. The best among the directions offered
// is the gap's, whichever order they come in.
TEST(BoundarySelectorTest, BestAmongLaysACoverageDragDownAGap) {
  const SurfaceLevel level = testing::Plate();
  absl::StatusOr<RegionMap> map = TwoGlassDrags(level);
  ASSERT_TRUE(map.ok()) << map.status();
  const BoundarySelector selector(level, kDragLengthMm, BoundarySelector::Friction(), 0.0, false, 1.0,
                                  /*far_gain_expected=*/true);
  const int between = selector.NearestVertex({-25, 0, 0}, 1.0);
  ASSERT_GE(between, 0);
  for (const auto& directions : {std::vector<Eigen::Vector3d>{Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY()},
                                 std::vector<Eigen::Vector3d>{Eigen::Vector3d::UnitY(), Eigen::Vector3d::UnitX()}}) {
    const BoundarySelection best = selector.BestDirectionAndAmong(*map, between, directions, {}).among;
    EXPECT_EQ(best.vertex, between);
    EXPECT_GT(best.gain, 0.0);
    EXPECT_NEAR(std::abs(best.direction.dot(Eigen::Vector3d::UnitY())), 1.0, 1e-12);
  }
  // Nothing to choose from, or nowhere to choose at: no selection.
  EXPECT_EQ(selector.BestDirectionAndAmong(*map, between, {}, {}).among.vertex, -1);
  const std::vector<Eigen::Vector3d> one = {Eigen::Vector3d::UnitX()};
  EXPECT_EQ(selector.BestDirectionAndAmong(*map, -1, one, {}).among.vertex, -1);
  EXPECT_EQ(selector.BestDirectionAndAmong(*map, static_cast<int>(level.limit_positions.size()), one, {}).among.vertex,
            -1);
  // The scan's answer from the same pass is BestDirection's.
  const BoundarySelection scan = selector.BestDirection(*map, between, {});
  const BoundarySelection same_pass = selector.BestDirectionAndAmong(*map, between, one, {}).best;
  EXPECT_EQ(same_pass.vertex, scan.vertex);
  EXPECT_EQ(same_pass.gain, scan.gain);
  EXPECT_EQ(same_pass.direction, scan.direction);
}

// The pebble's strip (MaterialMuRiskGain's comment): 260 mm^2 of masonite
// read 0.325 +- 0.017 from 80 mm of pieces, 0.02 from rubber's mu; a 16 mm
// drag along it lowers the chance it reads nearer rubber than its own truth
// from 0.556 to 0.519 (normal quantiles), worth 260 x 0.03 x 0.037.
TEST(MaterialMuRiskGainTest, IsTheFallInTheChanceOfReadingNearerAnotherMaterial) {
  EXPECT_NEAR(MaterialMuRiskGain(260.0, 0.017, 0.02, 80.0, 16.0, 0.03), 0.28895, 1e-5);
  // A longer drag settles more; a settled or an unseparated mu gains nothing.
  EXPECT_GT(MaterialMuRiskGain(260.0, 0.017, 0.02, 80.0, 32.0, 0.03), MaterialMuRiskGain(260.0, 0.017, 0.02, 80.0, 16.0, 0.03));
  EXPECT_LT(MaterialMuRiskGain(260.0, 0.002, 0.055, 80.0, 16.0, 0.03), 1e-12);
  EXPECT_EQ(MaterialMuRiskGain(260.0, 0.017, 0.0, 80.0, 16.0, 0.03), 0.0);
  EXPECT_EQ(MaterialMuRiskGain(260.0, 0.017, 0.02, 80.0, 16.0, 0.0), 0.0);
  EXPECT_EQ(MaterialMuRiskGain(260.0, 0.017, 0.02, 0.0, 16.0, 0.03), 0.0);  // no pieces: nothing to settle
}

// Rubber (0.305, known to 0.002) over x < 0; a masonite strip x in (5, 11)
// crossed by two 6 mm pieces reading `strip_mu` +- `strip_se`; wood (0.42)
// beyond x = 20.
absl::StatusOr<RegionMap> RubberStripWood(const SurfaceLevel& level, double strip_mu, double strip_se) {
  std::vector<MapPiece> pieces;
  int drag = 0;
  for (double x : {-45.0, -35.0, -25.0, -15.0, -5.0}) {
    pieces.push_back(testing::StraightPiece(drag++, {x, -20, 0}, {x, 20, 0}, 0.305, 0.0, true));
  }
  for (double y : {-15.0, 15.0}) {
    MapPiece strip = testing::MasonitePiece(drag++, {5, y, 0}, {11, y, 0});
    strip.piece.texture.mu = strip_mu;
    strip.piece.texture.mu_std = 0.13;  // masonite's per-pair spread: unlike rubber's
    strip.piece.mu_se = strip_se;
    pieces.push_back(strip);
  }
  for (double x : {25.0, 35.0, 45.0}) pieces.push_back(testing::WoodPiece(drag++, {x, -20, 0}, {x, 20, 0}));
  return testing::MapOfPieces(level, pieces);
}

TEST(BoundarySelectorTest, AMaterialWhoseMuIsNotSettledDrawsADragWhileItIsNearAnothers) {
  const SurfaceLevel level = testing::Plate();
  constexpr double kCost = 0.03;
  const BoundarySelector plain(level, kDragLengthMm, BoundarySelector::Friction(), kCost),
      risk(level, kDragLengthMm, BoundarySelector::Friction(), kCost, /*material_mu_risk=*/true);
  const int middle = plain.NearestVertex({8, 12, 0}, 3.0);
  ASSERT_GE(middle, 0);
  // Unsettled: 0.33 +- 0.03 per piece, 0.025 from rubber.
  absl::StatusOr<RegionMap> rough = RubberStripWood(level, 0.33, 0.03);
  ASSERT_TRUE(rough.ok()) << rough.status();
  // The drag is placed on the strip where a piece crossed it.
  const TextureRegion& under = rough->regions()[rough->region()[middle]];
  ASSERT_NEAR(under.statistics.mu, 0.33, 1e-9);
  const BoundarySelection without = plain.BestDirection(*rough, middle, {});
  const BoundarySelection with = risk.BestDirection(*rough, middle, {});
  ASSERT_GT(without.gain, 0.0);
  // The surplus is positive, and at most what a whole window of 16 mm on
  // the strip's material would gain: its area as the map draws it (a third
  // of each triangle to each corner), its two pieces' 12 mm behind its mu.
  double area = 0.0;
  const auto& x = level.limit_positions;
  for (const auto& t : level.triangles) {
    const double third = 0.5 * (x[t[1]] - x[t[0]]).cross(x[t[2]] - x[t[0]]).norm() / 3.0;
    for (int v : t) area += rough->regions()[rough->region()[v]].material == under.material ? third : 0.0;
  }
  const double whole = MaterialMuRiskGain(area, under.statistics.mu_se, 0.025, 12.0, 16.0, kCost);
  EXPECT_GT(with.gain, without.gain);
  EXPECT_LT(with.gain - without.gain, whole);
  // Settled: 0.36 +- 0.002, 0.055 from rubber; the risk adds nothing at all.
  absl::StatusOr<RegionMap> settled = RubberStripWood(level, 0.36, 0.002);
  ASSERT_TRUE(settled.ok()) << settled.status();
  const BoundarySelection a = plain.BestDirection(*settled, middle, {}), b = risk.BestDirection(*settled, middle, {});
  EXPECT_NEAR(a.gain, b.gain, 1e-12 * a.gain);
  EXPECT_EQ(a.direction, b.direction);
}

}  // namespace
}  // namespace surfmap
