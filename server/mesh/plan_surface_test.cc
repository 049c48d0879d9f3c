#include "server/mesh/plan_surface.h"

#include <gtest/gtest.h>
#include "server/mesh/primitive_meshes.h"

namespace surfmap {
namespace {

TEST(DerivedPlanSurfaceTest, ACoarseControlMeshIsPlannedAsItIs) {
  for (double spacing : {0.0, 13.0}) {
    absl::StatusOr<std::unique_ptr<LoopSurface>> derived =
        DerivedPlanSurface(MakeIcosahedron(40.0), /*facets=*/false, 2, spacing);
    ASSERT_TRUE(derived.ok()) << derived.status();
    EXPECT_EQ(*derived, nullptr) << spacing;
  }
}

TEST(DerivedPlanSurfaceTest, AScanIsSimplifiedAndFacetsAreAlwaysTheirOwn) {
  absl::StatusOr<ControlMesh> scan = MakeIcosphere(40.0, 5);  // 10,242 vertices ~1.2 mm apart
  ASSERT_TRUE(scan.ok()) << scan.status();
  absl::StatusOr<std::unique_ptr<LoopSurface>> simplified = DerivedPlanSurface(*scan, false, 1, 13.0);
  ASSERT_TRUE(simplified.ok()) << simplified.status();
  ASSERT_NE(*simplified, nullptr);
  EXPECT_LT((*simplified)->level(0).limit_positions.size(), scan->positions.size() / 10);
  // At spacing 0 a scan is its own control mesh; facets never are.
  absl::StatusOr<std::unique_ptr<LoopSurface>> own = DerivedPlanSurface(*scan, false, 1, 0.0);
  ASSERT_TRUE(own.ok()) << own.status();
  EXPECT_EQ(*own, nullptr);
  absl::StatusOr<std::unique_ptr<LoopSurface>> facets = DerivedPlanSurface(MakeCadBox(50.0), true, 1, 0.0);
  ASSERT_TRUE(facets.ok()) << facets.status();
  ASSERT_NE(*facets, nullptr);
  EXPECT_EQ((*facets)->level(0).limit_positions.size(), 8u);
}

}  // namespace
}  // namespace surfmap
