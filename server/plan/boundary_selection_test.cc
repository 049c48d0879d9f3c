#include "server/plan/boundary_selection.h"

#include <cmath>

#include <gtest/gtest.h>
#include "server/map/testing/map_pieces.h"

namespace surfmap {
namespace {

constexpr double kDragLengthMm = 20.0;

// Glass drags along y at x = -30 and -20, sandpaper at x = 20 and 30: the
// boundary somewhere in x in (-20, 20), pinned nowhere.
absl::StatusOr<RegionMap> UnpinnedBoundary(const SurfaceLevel& level) {
  absl::StatusOr<RegionMap> map = RegionMap::Create(level);
  if (!map.ok()) return map;
  std::vector<MapPiece> pieces;
  int drag = 0;
  for (double x : {-30.0, -20.0}) pieces.push_back(testing::StraightPiece(drag++, {x, -20, 0}, {x, 20, 0}, 0.13));
  for (double x : {20.0, 30.0}) pieces.push_back(testing::StraightPiece(drag++, {x, -20, 0}, {x, 20, 0}, 0.5));
  if (absl::Status s = map->SetPieces(pieces); !s.ok()) return s;
  return map;
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

}  // namespace
}  // namespace surfmap
