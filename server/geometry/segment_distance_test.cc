#include "server/geometry/segment_distance.h"

#include <gtest/gtest.h>

namespace surfmap {
namespace {

// Exact in binary floating point for these small integers and halves.
constexpr double kExact = 1e-12;

TEST(DistanceToSegment, InsideTheSpanItIsTheDistanceToTheLine) {
  EXPECT_NEAR(DistanceToSegment({1.0, 2.0, 0.0}, {0, 0, 0}, {4, 0, 0}), 2.0, kExact);
}

TEST(DistanceToSegment, BeyondAnEndItIsTheDistanceToThatEnd) {
  EXPECT_NEAR(DistanceToSegment({7.0, 4.0, 0.0}, {0, 0, 0}, {4, 0, 0}), 5.0, kExact);
  EXPECT_NEAR(DistanceToSegment({-3.0, 0.0, 4.0}, {0, 0, 0}, {4, 0, 0}), 5.0, kExact);
}

TEST(DistanceToSegment, ADegenerateSegmentIsAPoint) {
  EXPECT_NEAR(DistanceToSegment({0.0, 3.0, 4.0}, {0, 0, 0}, {0, 0, 0}), 5.0, kExact);
}

}  // namespace
}  // namespace surfmap
