#include "server/map/label_propagation.h"

#include <cmath>
#include <vector>

#include <gtest/gtest.h>
#include "server/map/testing/flat_grid_levels.h"

namespace surfmap {
namespace {

constexpr int kNx = 20, kNy = 10;  // a 20 x 10 mm plate, 1 mm cells

// Label 0 seeded along the plate's left edge, label 1 along its right edge:
// the fields are the linear ramps x / 20 and 1 - x / 20.
std::vector<SurfaceSeed> EdgeSeeds(const SurfaceLevel& level) {
  std::vector<SurfaceSeed> seeds;
  for (std::size_t t = 0; t < level.triangles.size(); ++t) {
    for (int k = 0; k < 3; ++k) {
      const int v = level.triangles[t][k];
      const double x = level.limit_positions[v].x();
      if (x != 0.0 && x != kNx) continue;
      Eigen::Vector3d barycentric = Eigen::Vector3d::Zero();
      barycentric[k] = 1.0;
      seeds.push_back({static_cast<int>(t), barycentric, x == 0.0 ? 0 : 1});
    }
  }
  return seeds;
}

TEST(LabelPropagationTest, TwoLabelsFromOppositeEdgesGiveLinearRamps) {
  const SurfaceLevel level = testing::MakeFlatGrid(kNx, kNy, 1.0);
  absl::StatusOr<LabelPropagation> propagation = LabelPropagation::Create(level);
  ASSERT_TRUE(propagation.ok()) << propagation.status();
  const std::vector<SurfaceSeed> seeds = EdgeSeeds(level);
  absl::StatusOr<std::vector<std::vector<double>>> fields = propagation->Propagate(seeds, 2);
  ASSERT_TRUE(fields.ok()) << fields.status();
  for (int v = 0; v < static_cast<int>(level.limit_positions.size()); ++v) {
    const double x = level.limit_positions[v].x() / kNx;
    // Soft seeds hold their targets to within ~10 % (kSeedStiffness).
    EXPECT_NEAR((*fields)[1][v], x, 0.1) << "vertex " << v;
    EXPECT_NEAR((*fields)[0][v] + (*fields)[1][v], 1.0, 1e-6) << "vertex " << v;
  }
}

// Before cotangents were capped, this sliver's weight (~1e149) set the seed
// stiffness and the regularisation: every field fell to ~0 a few vertices
// from its seeds (4e-5 at x = 17 mm instead of 0.85), and with more labels
// the ill-conditioned solve gave vertices far from the sliver the other
// side's label (the scan test's pebble: 97.8 % of its surface classified
// right instead of 99.8 %). Away from the fold the ramps hold as on the
// regular plate.
TEST(LabelPropagationTest, ASliverDoesNotSpoilTheFieldsAwayFromIt) {
  const SurfaceLevel level = testing::MakeFlatGridWithSliver(kNx, kNy);
  absl::StatusOr<LabelPropagation> propagation = LabelPropagation::Create(level);
  ASSERT_TRUE(propagation.ok()) << propagation.status();
  absl::StatusOr<std::vector<std::vector<double>>> fields = propagation->Propagate(EdgeSeeds(level), 2);
  ASSERT_TRUE(fields.ok()) << fields.status();
  const Eigen::Vector3d fold(kNx - 5.0, 1.0, 0.0);  // where the moved corner belongs
  int checked = 0;
  for (int v = 0; v < static_cast<int>(level.limit_positions.size()); ++v) {
    const Eigen::Vector3d& p = level.limit_positions[v];
    if ((p - fold).norm() < 3.0) continue;
    EXPECT_NEAR((*fields)[1][v], p.x() / kNx, 0.1) << "vertex " << v;
    ++checked;
  }
  EXPECT_GT(checked, 200);
}

}  // namespace
}  // namespace surfmap
