#include "server/plan/drag_direction.h"

#include <cmath>

#include <gtest/gtest.h>

namespace surfmap {
namespace {

// The three orientations a coverage drag may take: unit tangents 60 degrees
// apart, the key's own first, so choosing among them keeps the lattice's
// variety of orientations.
TEST(DragDirectionTest, VariedDirectionsAreTheKeysOwnThenTheOtherTwo) {
  const Eigen::Vector3d normal = Eigen::Vector3d(0.3, -0.5, 0.8).normalized();
  for (std::uint64_t key : {0u, 1u, 2u, 7u}) {
    const auto directions = VariedDragDirections(normal, key);
    EXPECT_LT((directions[0] - VariedDragDirection(normal, key)).norm(), 1e-12);
    for (int i = 0; i < 3; ++i) {
      EXPECT_NEAR(directions[i].norm(), 1.0, 1e-12);
      EXPECT_NEAR(directions[i].dot(normal), 0.0, 1e-12);
      const double cosine = directions[i].dot(directions[(i + 1) % 3]);
      EXPECT_NEAR(std::abs(cosine), 0.5, 1e-12) << "60 or 120 degrees apart";
    }
  }
}

}  // namespace
}  // namespace surfmap
