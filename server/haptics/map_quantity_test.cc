#include "server/haptics/map_quantity.h"

#include <cmath>

#include <gtest/gtest.h>
#include "server/haptics/test_meshes.h"

namespace surfmap::haptics {
namespace {

TEST(MapQuantityTest, EveryNameParsesToItsValues) {
  TextureMap map = testing::FlatPlate(2, 2.0);
  testing::PaintSplit(map, 1.0, testing::kRubber, testing::kMasonite);
  map.region[0] = -1;
  map.sigma[4] = 0.0;  // no roughness fit at vertex 4
  for (std::string_view name : {"mu", "mu_std", "sigma", "a1", "a2", "region", "boundary_probability"}) {
    absl::StatusOr<MapQuantity> q = ParseMapQuantity(name);
    ASSERT_TRUE(q.ok()) << name;
    EXPECT_EQ(MapQuantityName(*q), name);
    absl::StatusOr<std::vector<double>> values = MapQuantityValues(map, *q);
    ASSERT_TRUE(values.ok()) << name;
    EXPECT_EQ(values->size(), 9u);
  }
  EXPECT_EQ(MapQuantityTitle(MapQuantity::kSigma), "SIGMA (N)");
  EXPECT_DOUBLE_EQ((*MapQuantityValues(map, MapQuantity::kA1))[8], testing::kMasonite.a1);
  EXPECT_TRUE(std::isnan((*MapQuantityValues(map, MapQuantity::kA1))[4]));  // sigma 0: no fit
  EXPECT_TRUE(std::isnan((*MapQuantityValues(map, MapQuantity::kRegion))[0]));
  EXPECT_DOUBLE_EQ((*MapQuantityValues(map, MapQuantity::kRegion))[8], 1.0);
  EXPECT_EQ(ParseMapQuantity("friction").status().code(), absl::StatusCode::kInvalidArgument);
  map.sigma.clear();
  EXPECT_EQ(MapQuantityValues(map, MapQuantity::kSigma).status().code(), absl::StatusCode::kFailedPrecondition);
}

}  // namespace
}  // namespace surfmap::haptics
