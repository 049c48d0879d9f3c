#include "clients/rig/map_score.h"

#include <cmath>
#include <limits>

#include <gtest/gtest.h>

namespace surfmap::rig {
namespace {

// Glass everywhere except a sandpaper box over x >= 10.
Scene BoxScene() {
  Scene scene;
  scene.name = "box";
  scene.material_names = {"glass", "sandpaper"};
  scene.materials = {Material{0.13, 0, 0, 0.005}, Material{0.5, 0.3, 0.1, 0.25}};
  scene.default_material = 0;
  SceneRegion region;
  region.material = 1;
  region.shape = BoxRegion{Eigen::Vector3d(10, -100, -100), Eigen::Vector3d(100, 100, 100)};
  scene.regions.push_back(region);
  return scene;
}

cli::MapDocument FourVertexMap(std::vector<double> mu) {
  cli::MapDocument map;
  map.positions = {{0, 0, 0}, {5, 0, 0}, {20, 0, 0}, {30, 0, 0}};
  map.mu = std::move(mu);
  return map;
}

TEST(ScoreMapTest, KnownErrorsPerRegion) {
  // Glass vertices 0.13 and 0.23 (0.23 is still nearer glass's 0.13 than 0.5: right), sandpaper vertices
  // 0.5 and 0.2 (0.2 is nearer glass: wrong). Errors 0, 0.1, 0, -0.3.
  absl::StatusOr<MapScore> s = ScoreMap(BoxScene(), FourVertexMap({0.13, 0.23, 0.5, 0.2}));
  ASSERT_TRUE(s.ok()) << s.status();
  EXPECT_EQ(s->vertices, 4);
  EXPECT_EQ(s->vertices_with_mu, 4);
  EXPECT_NEAR(s->mu_rmse, std::sqrt((0.0 + 0.01 + 0.0 + 0.09) / 4), 1e-12);
  EXPECT_NEAR(s->mu_max_abs_error, 0.3, 1e-12);
  EXPECT_DOUBLE_EQ(s->classification_accuracy, 0.75);
  ASSERT_EQ(s->regions.size(), 2u);
  EXPECT_EQ(s->regions[0].name, "sandpaper (regions[0])");
  EXPECT_EQ(s->regions[0].vertices, 2);
  EXPECT_NEAR(s->regions[0].map_mu_mean, 0.35, 1e-12);
  EXPECT_NEAR(s->regions[0].map_mu_std, 0.15, 1e-12);
  EXPECT_EQ(s->regions[1].name, "glass (default)");
  EXPECT_NEAR(s->regions[1].map_mu_mean, 0.18, 1e-12);
  EXPECT_DOUBLE_EQ(s->regions[1].truth_mu, 0.13);
}

TEST(ScoreMapTest, UnknownValuesAreLeftOut) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  absl::StatusOr<MapScore> s = ScoreMap(BoxScene(), FourVertexMap({0.13, nan, 0.5, nan}));
  ASSERT_TRUE(s.ok()) << s.status();
  EXPECT_EQ(s->vertices_with_mu, 2);
  EXPECT_DOUBLE_EQ(s->mu_rmse, 0.0);
  EXPECT_DOUBLE_EQ(s->classification_accuracy, 1.0);
  EXPECT_EQ(s->regions[0].vertices, 2);
  EXPECT_EQ(s->regions[0].vertices_with_mu, 1);
}

TEST(ScoreMapTest, NeedsPositionsAndValues) {
  cli::MapDocument no_mesh;
  no_mesh.mu = {0.1, 0.2};
  EXPECT_EQ(ScoreMap(BoxScene(), no_mesh).status().code(), absl::StatusCode::kFailedPrecondition);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(ScoreMap(BoxScene(), FourVertexMap({nan, nan, nan, nan})).status().code(),
            absl::StatusCode::kFailedPrecondition);
}

TEST(ScoreMapTest, JsonAndTable) {
  absl::StatusOr<MapScore> s = ScoreMap(BoxScene(), FourVertexMap({0.13, 0.13, 0.5, 0.5}));
  ASSERT_TRUE(s.ok());
  nlohmann::json j = MapScoreToJson(*s, "box");
  EXPECT_EQ(j["scene"], "box");
  EXPECT_DOUBLE_EQ(j["mu_rmse"].get<double>(), 0.0);
  EXPECT_EQ(j["regions"][0]["material"], "sandpaper");
  const std::string table = FormatMapScore(*s, "box");
  EXPECT_NE(table.find("vertices classified right  100.0 %"), std::string::npos) << table;
}

}  // namespace
}  // namespace surfmap::rig
