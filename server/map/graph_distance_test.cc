#include "server/map/graph_distance.h"

#include <cmath>

#include <gtest/gtest.h>
#include "server/map/material_classification.h"
#include "server/map/testing/flat_grid_levels.h"

namespace surfmap {
namespace {

TEST(NearestSourceDistanceTest, FollowsEdgesOfTheGrid) {
  const auto level = testing::MakeFlatGrid(4, 4, 10.0);  // diagonals from (i,j) to (i+1,j+1)
  const int sources[] = {0};
  const NearestSource near = NearestSourceDistance(level, sources);
  EXPECT_NEAR(near.distance_mm[24], 4 * 10.0 * std::sqrt(2.0), 1e-9);  // along the diagonals
  EXPECT_NEAR(near.distance_mm[4], 40.0, 1e-9);
  EXPECT_NEAR(near.distance_mm[20], 40.0, 1e-9);
  EXPECT_NEAR(near.distance_mm[0], 0.0, 0.0);
  for (int s : near.source) EXPECT_EQ(s, 0);
}

TEST(NearestSourceDistanceTest, AssignsEachVertexToItsNearestSourceAndBreaksTiesByIndex) {
  const auto level = testing::MakeFlatGrid(4, 0 + 1, 10.0);  // 5 x 2 vertices
  const int sources[] = {4, 0};
  const NearestSource near = NearestSourceDistance(level, sources);
  EXPECT_EQ(near.source[1], 1);
  EXPECT_EQ(near.source[3], 0);
  EXPECT_EQ(near.source[2], 0);  // 20 mm from both: the lower source index
  EXPECT_NEAR(near.distance_mm[2], 20.0, 1e-12);
}

TEST(NearestSourceDistanceTest, UnreachableWithoutSources) {
  const auto level = testing::MakeFlatGrid(2, 2, 1.0);
  const NearestSource near = NearestSourceDistance(level, {});
  EXPECT_TRUE(std::isinf(near.distance_mm[0]));
  EXPECT_EQ(near.source[0], -1);
}

TEST(ClassifyNearestMaterialTest, PicksTheNearestMaterial) {
  const double mu[] = {0.1, 0.3, 0.31, 0.49, 0.314};
  const double materials[] = {0.13, 0.5};
  auto classes = ClassifyNearestMaterial(mu, materials);
  ASSERT_TRUE(classes.ok());
  EXPECT_EQ(*classes, (std::vector<int>{0, 0, 0, 1, 0}));
  const double tie[] = {0.5};  // exactly halfway in binary
  const double tie_materials[] = {0.25, 0.75};
  EXPECT_EQ((*ClassifyNearestMaterial(tie, tie_materials))[0], 0);
  EXPECT_FALSE(ClassifyNearestMaterial(mu, {}).ok());
  const double bad[] = {NAN};
  EXPECT_FALSE(ClassifyNearestMaterial(bad, materials).ok());
}

}  // namespace
}  // namespace surfmap
