#include "clients/sim/rig/surface_score.h"

#include <cmath>

#include <gtest/gtest.h>
#include "clients/sim/rig/scene_meshes.h"

namespace surfmap {
namespace {

// The plate (200 x 150 mm in z = 0) with a rubber stripe x in [-40, -10]
// across its whole height (so its only boundaries are the lines x = -40 and
// x = -10) on wood.
Scene StripePlate() {
  Scene scene;
  scene.name = "stripe_plate";
  scene.mesh = *MakeBuiltInSceneMesh("plate");
  scene.material_names = {"rubber", "wood"};
  scene.materials = {Material{0.305, 0.60, 0.25, 0.11}, Material{0.42, 0.0, 0.0, 0.005}};
  scene.default_material = 1;
  SceneRegion stripe;
  stripe.material = 0;
  stripe.shape = BoxRegion{Eigen::Vector3d(-40, -100, -5), Eigen::Vector3d(-10, 100, 5)};
  scene.regions = {stripe};
  return scene;
}

MapReader StripeMap(double from, double to) {
  return [from, to](const Eigen::Vector3d& p) -> absl::StatusOr<MapReading> {
    MapReading r;
    const bool rubber = p.x() >= from && p.x() <= to;
    r.mu = rubber ? 0.305 : 0.42;
    r.has_roughness = rubber;
    r.a1 = 0.6;
    r.a2 = 0.25;
    r.sigma = 0.11;
    return r;
  };
}

TEST(SurfaceScoreTest, TheTruthScoresPerfectly) {
  auto scorer = SurfaceScorer::Create(StripePlate());
  ASSERT_TRUE(scorer.ok()) << scorer.status();
  ASSERT_EQ(scorer->points().size(), 5000u);
  auto score = scorer->Score(StripeMap(-40, -10));
  ASSERT_TRUE(score.ok()) << score.status();
  EXPECT_EQ(score->classified_right, 1.0);
  EXPECT_EQ(score->mu_rmse, 0.0);
  // Both boundaries found to the bisection's resolution: level-4 edges of the
  // plate are <= 1.6 mm, halved 6 times, 0.025 mm; the map's own bisection
  // adds as much.
  EXPECT_LT(score->boundary_error_mm, 0.05);
  EXPECT_LT(score->missed_boundary_mm, 0.05);
  EXPECT_TRUE(std::isnan(score->misclassified_distance_mm));
  ASSERT_EQ(score->regions.size(), 2u);
  const RegionScore& stripe = score->regions[0];
  EXPECT_EQ(stripe.name, "rubber (regions[0])");
  // Area share: 30 of 200 mm of width; 5000 points give a binomial se of 0.5 %.
  EXPECT_NEAR(static_cast<double>(stripe.points) / 5000, 0.15, 0.02);
  EXPECT_TRUE(stripe.rough);
  EXPECT_FALSE(score->regions[1].rough);  // sigma 0.005 N: below the sensor
  EXPECT_EQ(stripe.points_with_roughness, stripe.points);
  EXPECT_DOUBLE_EQ(stripe.a1_median, 0.6);
  EXPECT_DOUBLE_EQ(stripe.sigma_median, 0.11);
}

TEST(SurfaceScoreTest, AShiftedBoundaryIsMeasuredInMillimetres) {
  auto scorer = SurfaceScorer::Create(StripePlate());
  ASSERT_TRUE(scorer.ok());
  // The map puts both edges 2 mm to the right.
  auto score = scorer->Score(StripeMap(-38, -8));
  ASSERT_TRUE(score.ok());
  EXPECT_NEAR(score->boundary_error_mm, 2.0, 0.05);
  EXPECT_NEAR(score->missed_boundary_mm, 2.0, 0.05);
  // Misclassified: the two 2 mm bands, 4 of 200 mm of width (se ~0.3 %).
  EXPECT_NEAR(score->classified_right, 0.98, 0.01);
  // ... lying between 0 and 2 mm from a true boundary: 1 mm on average.
  EXPECT_NEAR(score->misclassified_distance_mm, 1.0, 0.1);
  // RMSE: the 2 % misclassified are off by 0.115.
  EXPECT_NEAR(score->mu_rmse, 0.115 * std::sqrt(0.02), 0.004);
}

TEST(SurfaceScoreTest, AMapWithoutTheStripeMissesItsBoundaries) {
  auto scorer = SurfaceScorer::Create(StripePlate());
  ASSERT_TRUE(scorer.ok());
  auto score = scorer->Score(StripeMap(1000, 1001));  // wood everywhere
  ASSERT_TRUE(score.ok());
  EXPECT_EQ(score->map_boundary_points, 0);
  EXPECT_TRUE(std::isnan(score->boundary_error_mm));
  EXPECT_EQ(score->regions[0].classified_right, 0.0);
  EXPECT_EQ(score->regions[1].classified_right, 1.0);
  EXPECT_EQ(score->regions[0].points_with_roughness, 0);
  EXPECT_TRUE(std::isnan(score->regions[0].a1_median));
}

// A 4 mm stripe: 2 % of the plate, ~100 of the 5,000 points.
Scene NarrowStripePlate() {
  Scene scene = StripePlate();
  scene.regions[0].shape = BoxRegion{Eigen::Vector3d(-14, -100, -5), Eigen::Vector3d(-10, 100, 5)};
  return scene;
}

TEST(SurfaceScoreTest, ASmallRegionIsScoredOnEnoughPointsOfItsOwn) {
  auto scorer = SurfaceScorer::Create(NarrowStripePlate());
  ASSERT_TRUE(scorer.ok()) << scorer.status();
  // The map puts the stripe's edges 0.6 mm to the right: 3.4 of its 4 mm,
  // 85 %, are right.
  auto score = scorer->Score(StripeMap(-13.4, -9.4));
  ASSERT_TRUE(score.ok()) << score.status();
  const RegionScore& stripe = score->regions[0];
  EXPECT_EQ(stripe.points, 400);
  EXPECT_GT(stripe.extra_points, 250);  // ~100 of the uniform 5,000 fell in it (se 10)
  EXPECT_EQ(score->regions[1].extra_points, 0);
  // 400 points: a binomial se of 1.8 % at 85 %; 3.3 se.
  EXPECT_NEAR(stripe.classified_right, 0.85, 0.06);
  // The overall share and the RMSE stay the area-uniform sample's: a 0.6 mm
  // band on each side of 200 mm of width is 0.6 % wrong (se ~0.1 %).
  EXPECT_EQ(score->points, 5000);
  EXPECT_NEAR(score->classified_right, 1.0 - 1.2 / 200.0, 0.004);
  EXPECT_EQ(static_cast<int>(scorer->points().size()), 5000 + stripe.extra_points);
  // Every wrong point is listed, the random ones first; the stripe's own extra
  // ones say where its row lost its share: within the 0.6 mm it was shifted of
  // a true boundary point, which lie up to 1.6 mm apart (level-4 edges), so
  // within hypot(0.6, 0.8) = 1 mm of the nearest.
  int region_only_wrong = 0, stripe_wrong = 0;
  bool random_first = true, seen_region_only = false;
  for (const MisclassifiedPoint& p : score->misclassified) {
    random_first &= !(seen_region_only && !p.region_only);
    seen_region_only |= p.region_only;
    region_only_wrong += p.region_only;
    stripe_wrong += p.region == 0;
    EXPECT_LT(p.boundary_distance_mm, 1.0);
    if (p.region_only) {
      EXPECT_EQ(p.region, 0);
    }
  }
  EXPECT_TRUE(random_first);
  EXPECT_GT(region_only_wrong, 0);
  EXPECT_EQ(stripe_wrong, std::lround((1.0 - stripe.classified_right) * stripe.points));

  SurfaceScoreOptions uniform_only;
  uniform_only.min_region_points = 0;
  auto plain = SurfaceScorer::Create(NarrowStripePlate(), uniform_only);
  ASSERT_TRUE(plain.ok());
  EXPECT_EQ(plain->points().size(), 5000u);
  auto plain_score = plain->Score(StripeMap(-13.4, -9.4));
  ASSERT_TRUE(plain_score.ok());
  EXPECT_EQ(plain_score->regions[0].extra_points, 0);
  EXPECT_EQ(plain_score->classified_right, score->classified_right) << "extra points changed the overall share";
}

TEST(SurfaceScoreTest, ReaderErrorsAndBadValuesAreNamed) {
  auto scorer = SurfaceScorer::Create(StripePlate());
  ASSERT_TRUE(scorer.ok());
  auto failing = scorer->Score([](const Eigen::Vector3d&) -> absl::StatusOr<MapReading> {
    return absl::FailedPreconditionError("no map");
  });
  EXPECT_EQ(failing.status().code(), absl::StatusCode::kFailedPrecondition);
  EXPECT_NE(failing.status().message().find("map at ("), std::string::npos);
  auto nan = scorer->Score([](const Eigen::Vector3d&) -> absl::StatusOr<MapReading> {
    return MapReading{std::nan(""), false, 0, 0, 0};
  });
  EXPECT_NE(nan.status().message().find("mu is nan"), std::string::npos);
  SurfaceScoreOptions bad;
  bad.points = 0;
  EXPECT_EQ(SurfaceScorer::Create(StripePlate(), bad).status().message(),
            "surface score options: points 0 must be >= 1");
}

}  // namespace
}  // namespace surfmap
