#include "server/mesh/loop_surface.h"

#include <cmath>
#include <cstdio>
#include <numbers>
#include <random>
#include <set>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <Eigen/Geometry>
#include "server/mesh/primitive_meshes.h"
#include "server/mesh/test_data.h"
#include "server/mesh/triangle_bvh.h"

namespace surfmap {
namespace {

using ::testing::HasSubstr;

std::unique_ptr<LoopSurface> MustCreate(const ControlMesh& mesh, int level) {
  absl::StatusOr<std::unique_ptr<LoopSurface>> surface = LoopSurface::Create(mesh, level);
  EXPECT_TRUE(surface.ok()) << surface.status();
  return surface.ok() ? std::move(*surface) : nullptr;
}

TEST(LoopSurfaceTest, RefinementCountsFollowLoop) {
  std::unique_ptr<LoopSurface> surface = MustCreate(MakeTetrahedron(10.0), 3);
  ASSERT_NE(surface, nullptr);
  ASSERT_EQ(surface->max_level(), 3);
  for (int k = 0; k < 3; ++k) {
    const SurfaceLevel& coarse = surface->level(k);
    const SurfaceLevel& fine = surface->level(k + 1);
    EXPECT_EQ(fine.positions.size(), coarse.positions.size() + coarse.edges.size()) << k;
    EXPECT_EQ(fine.triangles.size(), 4 * coarse.triangles.size()) << k;
    EXPECT_EQ(fine.edges.size(), 2 * coarse.edges.size() + 3 * coarse.triangles.size()) << k;
  }
  EXPECT_EQ(surface->finest().positions.size(), 130u);
  EXPECT_EQ(surface->finest().triangles.size(), 256u);
  EXPECT_EQ(surface->finest().limit_positions.size(), 130u);
  EXPECT_EQ(surface->finest().limit_normals.size(), 130u);
  EXPECT_TRUE(surface->finest().edge_child_vertex.empty());
  EXPECT_TRUE(surface->level(0).parent_edge.empty());
}

TEST(LoopSurfaceTest, RejectsBadLevelAndBadMesh) {
  for (int level : {-1, 7}) {
    absl::StatusOr<std::unique_ptr<LoopSurface>> surface = LoopSurface::Create(MakeTetrahedron(1.0), level);
    ASSERT_FALSE(surface.ok());
    EXPECT_EQ(surface.status().code(), absl::StatusCode::kInvalidArgument);
    EXPECT_THAT(std::string(surface.status().message()), HasSubstr("out of range 0..6"));
  }
  ControlMesh broken = MakeTetrahedron(1.0);
  broken.triangles[0] = {0, 0, 1};
  EXPECT_THAT(std::string(LoopSurface::Create(broken, 2).status().message()), HasSubstr("repeats a vertex"));

  absl::StatusOr<ControlMesh> big = MakeIcosphere(10.0, 5);  // 20480 faces
  ASSERT_TRUE(big.ok());
  EXPECT_THAT(std::string(LoopSurface::Create(*big, 6).status().message()), HasSubstr("more than the limit"));
}

TEST(LoopSurfaceTest, LevelWithinTriangleLimitStepsDownOnlyWhereNeeded) {
  absl::StatusOr<ControlMesh> scan = MakeIcosphere(10.0, 5);  // 20,480 faces: level 3 is 1.3M, level 4 5.2M
  ASSERT_TRUE(scan.ok());
  EXPECT_EQ(LevelWithinTriangleLimit(*scan, 4), 3);
  EXPECT_EQ(LevelWithinTriangleLimit(*scan, 3), 3);
  EXPECT_EQ(LevelWithinTriangleLimit(*scan, 1), 1);
  EXPECT_EQ(LevelWithinTriangleLimit(MakeIcosahedron(1.0), 6), 6);  // 81,920 triangles
  EXPECT_EQ(LevelWithinTriangleLimit(MakeIcosahedron(1.0), 9), 6);  // clamped to the range
  EXPECT_EQ(LevelWithinTriangleLimit(MakeIcosahedron(1.0), -1), 0);
  EXPECT_TRUE(LoopSurface::Create(*scan, LevelWithinTriangleLimit(*scan, 4)).ok());
}

TEST(LoopSurfaceTest, LevelZeroIsTheControlMesh) {
  const ControlMesh ico = MakeIcosahedron(25.0);
  std::unique_ptr<LoopSurface> surface = MustCreate(ico, 2);
  ASSERT_NE(surface, nullptr);
  EXPECT_EQ(surface->level(0).positions, ico.positions);
  EXPECT_EQ(surface->level(0).triangles, ico.triangles);
}

TEST(LoopSurfaceTest, TopologyTablesAreConsistent) {
  std::unique_ptr<LoopSurface> surface = MustCreate(MakeOctahedron(20.0), 3);
  ASSERT_NE(surface, nullptr);
  for (int k = 0; k <= 3; ++k) {
    SCOPED_TRACE(k);
    const SurfaceLevel& level = surface->level(k);
    std::set<std::pair<int, int>> from_triangles;
    for (const auto& t : level.triangles) {
      for (int i = 0; i < 3; ++i) {
        from_triangles.insert({std::min(t[i], t[(i + 1) % 3]), std::max(t[i], t[(i + 1) % 3])});
      }
    }
    std::set<std::pair<int, int>> listed;
    for (const auto& e : level.edges) {
      EXPECT_LT(e[0], e[1]);
      listed.insert({e[0], e[1]});
    }
    EXPECT_EQ(listed.size(), level.edges.size());  // each edge once
    EXPECT_EQ(listed, from_triangles);
    std::size_t degree_sum = 0;
    for (int v = 0; v < static_cast<int>(level.neighbors.size()); ++v) {
      const std::vector<int>& around = level.neighbors[v];
      EXPECT_TRUE(std::is_sorted(around.begin(), around.end()));
      degree_sum += around.size();
      for (int w : around) EXPECT_TRUE(listed.count({std::min(v, w), std::max(v, w)})) << v << " " << w;
    }
    EXPECT_EQ(degree_sum, 2 * level.edges.size());
  }
}

// The numbering contract, checked against independent refinements: a surface
// refined only to level k must agree with the level-k prefix of a deeper one,
// and vertex i stays vertex i (near its old place) one level down.
TEST(LoopSurfaceTest, NumberingContractHoldsAcrossLevels) {
  const ControlMesh ico = MakeIcosahedron(25.0);
  std::unique_ptr<LoopSurface> deep = MustCreate(ico, 4);
  ASSERT_NE(deep, nullptr);
  for (int k = 0; k < 4; ++k) {
    SCOPED_TRACE(k);
    std::unique_ptr<LoopSurface> shallow = MustCreate(ico, k);
    ASSERT_NE(shallow, nullptr);
    const SurfaceLevel& mine = shallow->finest();
    const SurfaceLevel& coarse = deep->level(k);
    const SurfaceLevel& fine = deep->level(k + 1);
    ASSERT_EQ(mine.positions.size(), coarse.positions.size());
    double edge_length = 0.0;
    for (const auto& e : coarse.edges) edge_length += (coarse.positions[e[0]] - coarse.positions[e[1]]).norm();
    edge_length /= coarse.edges.size();
    for (std::size_t v = 0; v < mine.positions.size(); ++v) {
      // Limit of vertex v computed at level k vs at level 4, independently.
      EXPECT_LT((mine.limit_positions[v] - fine.limit_positions[v]).norm(), 1e-9) << v;
      EXPECT_GT(mine.limit_normals[v].dot(fine.limit_normals[v]), 1.0 - 1e-9) << v;
      EXPECT_LT((mine.positions[v] - coarse.positions[v]).norm(), 1e-12) << v;
      // Loop's vertex rule moves a vertex by a fraction of an edge.
      EXPECT_LT((fine.positions[v] - coarse.positions[v]).norm(), 0.25 * edge_length) << v;
    }
    ASSERT_EQ(coarse.edge_child_vertex.size(), coarse.edges.size());
    ASSERT_EQ(fine.parent_edge.size(), fine.positions.size());
    for (std::size_t e = 0; e < coarse.edges.size(); ++e) {
      const int child = coarse.edge_child_vertex[e];
      ASSERT_GE(child, static_cast<int>(coarse.positions.size()));
      EXPECT_EQ(fine.parent_edge[child], static_cast<int>(e));
      const Eigen::Vector3d midpoint = 0.5 * (coarse.positions[coarse.edges[e][0]] + coarse.positions[coarse.edges[e][1]]);
      EXPECT_LT((fine.positions[child] - midpoint).norm(), 0.25 * edge_length) << e;
      // The child is a neighbour of both ends of its parent edge.
      for (int end : coarse.edges[e]) {
        const auto& around = fine.neighbors[end];
        EXPECT_TRUE(std::binary_search(around.begin(), around.end(), child));
      }
    }
    for (std::size_t v = 0; v < coarse.positions.size(); ++v) EXPECT_EQ(fine.parent_edge[v], -1);
  }
}

TEST(LoopSurfaceTest, IcosahedronLimitIsNearlyASphereWithOutwardNormals) {
  const double radius = 25.0;
  std::unique_ptr<LoopSurface> surface = MustCreate(MakeIcosahedron(radius), 4);
  ASSERT_NE(surface, nullptr);
  const SurfaceLevel& finest = surface->finest();
  double lo = INFINITY, hi = 0.0, worst_normal = 1.0;
  for (std::size_t v = 0; v < finest.limit_positions.size(); ++v) {
    const Eigen::Vector3d& p = finest.limit_positions[v];
    lo = std::min(lo, p.norm());
    hi = std::max(hi, p.norm());
    EXPECT_NEAR(finest.limit_normals[v].norm(), 1.0, 1e-12);
    worst_normal = std::min(worst_normal, finest.limit_normals[v].dot(p.normalized()));
  }
  // Loop's limit of an icosahedron is round to ~1%, smaller than the
  // control polyhedron's circumsphere.
  EXPECT_GT(lo, 0.65 * radius);
  std::printf("icosahedron r=%g level 4 limit radius %.4f..%.4f\n", radius, lo, hi);
  EXPECT_LT(hi, radius);
  EXPECT_LT((hi - lo) / hi, 0.02) << lo << " " << hi;
  EXPECT_GT(worst_normal, 0.995);
  // Consistent with the counter-clockwise winding of every finest triangle.
  for (const auto& t : finest.triangles) {
    const Eigen::Vector3d& a = finest.limit_positions[t[0]];
    const Eigen::Vector3d face = (finest.limit_positions[t[1]] - a).cross(finest.limit_positions[t[2]] - a);
    for (int i = 0; i < 3; ++i) EXPECT_GT(face.dot(finest.limit_normals[t[i]]), 0.0);
  }
}

TEST(LoopSurfaceTest, PlateStaysFlatWithCornersAndUpNormals) {
  absl::StatusOr<ControlMesh> plate = MakeGridPlate(120.0, 80.0, 6, 4);
  ASSERT_TRUE(plate.ok());
  std::unique_ptr<LoopSurface> surface = MustCreate(*plate, 3);
  ASSERT_NE(surface, nullptr);
  const SurfaceLevel& finest = surface->finest();
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(INFINITY), hi = -lo;
  for (std::size_t v = 0; v < finest.limit_positions.size(); ++v) {
    EXPECT_NEAR(finest.limit_positions[v].z(), 0.0, 1e-12);
    EXPECT_GT(finest.limit_normals[v].z(), 1.0 - 1e-12) << v;
    lo = lo.cwiseMin(finest.limit_positions[v]);
    hi = hi.cwiseMax(finest.limit_positions[v]);
  }
  // EDGE_AND_CORNER: the limit surface covers the whole plate.
  EXPECT_NEAR(lo.x(), -60.0, 1e-9);
  EXPECT_NEAR(hi.x(), 60.0, 1e-9);
  EXPECT_NEAR(lo.y(), -40.0, 1e-9);
  EXPECT_NEAR(hi.y(), 40.0, 1e-9);
  // Every corner vertex of the control grid stays on its corner.
  for (int nx : {5, 6}) {
    absl::StatusOr<ControlMesh> grid = MakeGridPlate(120.0, 80.0, nx, 3);
    ASSERT_TRUE(grid.ok());
    std::unique_ptr<LoopSurface> s = MustCreate(*grid, 2);
    ASSERT_NE(s, nullptr);
    for (int corner : {0, nx, (nx + 1) * 3, (nx + 1) * 4 - 1}) {
      EXPECT_LT((s->finest().limit_positions[corner] - grid->positions[corner]).norm(), 1e-9) << nx << " " << corner;
    }
  }
}

TEST(LoopSurfaceTest, ClosestPointMatchesBruteForce) {
  absl::StatusOr<ControlMesh> sphere = MakeIcosphere(30.0, 1);
  ASSERT_TRUE(sphere.ok());
  std::unique_ptr<LoopSurface> surface = MustCreate(*sphere, 3);
  ASSERT_NE(surface, nullptr);
  const SurfaceLevel& finest = surface->finest();
  std::mt19937_64 rng(20240611);
  std::uniform_real_distribution<double> coordinate(-60.0, 60.0);
  for (int i = 0; i < 400; ++i) {
    const Eigen::Vector3d q(coordinate(rng), coordinate(rng), coordinate(rng));
    double best = INFINITY;
    for (const auto& t : finest.triangles) {
      best = std::min(best, ClosestPointOnTriangle(q, finest.limit_positions[t[0]], finest.limit_positions[t[1]],
                                                   finest.limit_positions[t[2]])
                                .squared_distance);
    }
    const SurfacePoint hit = surface->ClosestPoint(q);
    ASSERT_GE(hit.triangle, 0);
    EXPECT_NEAR(hit.distance, std::sqrt(best), 1e-9) << i;
    EXPECT_NEAR((hit.position - q).norm(), hit.distance, 1e-9);
    EXPECT_NEAR(hit.barycentric.sum(), 1.0, 1e-12);
    EXPECT_GE(hit.barycentric.minCoeff(), -1e-12);
    const auto& t = finest.triangles[hit.triangle];
    const Eigen::Vector3d rebuilt = hit.barycentric[0] * finest.limit_positions[t[0]] +
                                    hit.barycentric[1] * finest.limit_positions[t[1]] +
                                    hit.barycentric[2] * finest.limit_positions[t[2]];
    EXPECT_LT((rebuilt - hit.position).norm(), 1e-9);
    EXPECT_NEAR(hit.normal.norm(), 1.0, 1e-12);
    EXPECT_GT(hit.normal.dot(hit.position.normalized()), 0.99);
  }
}

TEST(LoopSurfaceTest, ClosestPointOfASurfacePointIsItself) {
  std::unique_ptr<LoopSurface> surface = MustCreate(MakeOctahedron(20.0), 3);
  ASSERT_NE(surface, nullptr);
  const SurfaceLevel& finest = surface->finest();
  for (std::size_t v = 0; v < finest.limit_positions.size(); v += 7) {
    const SurfacePoint hit = surface->ClosestPoint(finest.limit_positions[v]);
    EXPECT_LT(hit.distance, 1e-9);
    EXPECT_GT(hit.normal.dot(finest.limit_normals[v]), 1.0 - 1e-9);
  }
}

TEST(LoopSurfaceTest, DragPathOnANearSphereFollowsAGreatCircle) {
  std::unique_ptr<LoopSurface> surface = MustCreate(MakeIcosahedron(50.0), 4);
  ASSERT_NE(surface, nullptr);
  std::mt19937_64 rng(7);
  std::normal_distribution<double> gauss;
  for (int trial = 0; trial < 10; ++trial) {
    SCOPED_TRACE(trial);
    const Eigen::Vector3d start = 50.0 * Eigen::Vector3d(gauss(rng), gauss(rng), gauss(rng)).normalized();
    const Eigen::Vector3d direction(gauss(rng), gauss(rng), gauss(rng));
    absl::StatusOr<SurfacePath> path = surface->TraceDragPath(start, direction, 20.0, 0.25);
    ASSERT_TRUE(path.ok()) << path.status();
    ASSERT_EQ(path->points.size(), path->normals.size());
    EXPECT_NEAR(path->length_mm, 20.0, 1e-6);
    double polyline = 0.0;
    for (std::size_t i = 1; i < path->points.size(); ++i) {
      polyline += (path->points[i] - path->points[i - 1]).norm();
    }
    EXPECT_NEAR(polyline, path->length_mm, 1e-9);
    EXPECT_GE(path->points.size(), 81u);
    // On the surface; the first step goes along the projected direction.
    for (const Eigen::Vector3d& p : path->points) EXPECT_LT(surface->ClosestPoint(p).distance, 1e-9);
    const SurfacePoint origin = surface->ClosestPoint(start);
    const Eigen::Vector3d first = (path->points[1] - path->points[0]).normalized();
    const Eigen::Vector3d wanted = (direction - direction.dot(origin.normal) * origin.normal).normalized();
    EXPECT_GT(first.dot(wanted), 0.999);
    // A geodesic on a near-sphere stays near the great-circle plane through
    // the centre, the start and the start tangent.
    const Eigen::Vector3d plane = path->points[0].cross(wanted).normalized();
    double off_plane = 0.0;
    for (const Eigen::Vector3d& p : path->points) off_plane = std::max(off_plane, std::abs(p.dot(plane)));
    EXPECT_LT(off_plane, 0.5);
    const double r = path->points[0].norm();
    EXPECT_NEAR((path->points.back() - path->points[0]).norm(), 2 * r * std::sin(10.0 / r), 0.2);
  }
}

TEST(LoopSurfaceTest, DragPathOnAPlateIsStraightAndStopsAtTheBoundary) {
  absl::StatusOr<ControlMesh> plate = MakeGridPlate(120.0, 80.0, 6, 4);
  ASSERT_TRUE(plate.ok());
  std::unique_ptr<LoopSurface> surface = MustCreate(*plate, 2);
  ASSERT_NE(surface, nullptr);

  absl::StatusOr<SurfacePath> path =
      surface->TraceDragPath(Eigen::Vector3d(-10, 5, 3), Eigen::Vector3d(1, 1, 1), 20.0, 0.3);
  ASSERT_TRUE(path.ok()) << path.status();
  EXPECT_LT((path->points.front() - Eigen::Vector3d(-10, 5, 0)).norm(), 1e-12);
  const Eigen::Vector3d end = Eigen::Vector3d(-10, 5, 0) + 20.0 * Eigen::Vector3d(1, 1, 0).normalized();
  EXPECT_LT((path->points.back() - end).norm(), 1e-6);
  for (const Eigen::Vector3d& n : path->normals) EXPECT_GT(n.z(), 1.0 - 1e-12);

  // Along the edge of the plate is fine; across it is not.
  EXPECT_TRUE(surface->TraceDragPath(Eigen::Vector3d(-20, -40, 0), Eigen::Vector3d(1, 0, 0), 20.0).ok());
  absl::StatusOr<SurfacePath> off =
      surface->TraceDragPath(Eigen::Vector3d(50, 0, 0), Eigen::Vector3d(1, 0.2, 0), 20.0);
  ASSERT_FALSE(off.ok());
  EXPECT_EQ(off.status().code(), absl::StatusCode::kOutOfRange);
  EXPECT_THAT(std::string(off.status().message()), HasSubstr("open boundary"));
  EXPECT_THAT(std::string(off.status().message()), HasSubstr("of 20.000 mm"));
}

TEST(LoopSurfaceTest, DragPathRejectsBadArguments) {
  absl::StatusOr<ControlMesh> plate = MakeGridPlate(100.0, 100.0, 2, 2);
  ASSERT_TRUE(plate.ok());
  std::unique_ptr<LoopSurface> surface = MustCreate(*plate, 1);
  ASSERT_NE(surface, nullptr);
  const Eigen::Vector3d start(0, 0, 0);
  EXPECT_THAT(std::string(surface->TraceDragPath(start, Eigen::Vector3d::Zero(), 10).status().message()),
              HasSubstr("zero"));
  EXPECT_THAT(std::string(surface->TraceDragPath(start, Eigen::Vector3d(0, 0, -2), 10).status().message()),
              HasSubstr("along the surface normal"));
  EXPECT_THAT(std::string(surface->TraceDragPath(start, Eigen::Vector3d::UnitX(), 0).status().message()),
              HasSubstr("length"));
  EXPECT_THAT(std::string(surface->TraceDragPath(start, Eigen::Vector3d::UnitX(), 10, -1).status().message()),
              HasSubstr("step"));
  EXPECT_THAT(std::string(surface->TraceDragPath(start, Eigen::Vector3d(NAN, 0, 0), 10).status().message()),
              HasSubstr("not finite"));
}

TEST(LoopSurfaceTest, DefaultDragDirectionIsATangentAxis) {
  absl::StatusOr<ControlMesh> plate = MakeGridPlate(100.0, 100.0, 2, 2);
  ASSERT_TRUE(plate.ok());
  std::unique_ptr<LoopSurface> flat = MustCreate(*plate, 1);
  ASSERT_NE(flat, nullptr);
  EXPECT_LT((flat->DefaultDragDirection(3) - Eigen::Vector3d::UnitX()).norm(), 1e-12);
  EXPECT_EQ(flat->DefaultDragDirection(-1), Eigen::Vector3d::Zero());
  EXPECT_EQ(flat->DefaultDragDirection(100000), Eigen::Vector3d::Zero());

  std::unique_ptr<LoopSurface> round = MustCreate(MakeIcosahedron(25.0), 3);
  ASSERT_NE(round, nullptr);
  for (int v = 0; v < static_cast<int>(round->finest().limit_normals.size()); ++v) {
    const Eigen::Vector3d d = round->DefaultDragDirection(v);
    EXPECT_NEAR(d.norm(), 1.0, 1e-12);
    EXPECT_NEAR(d.dot(round->finest().limit_normals[v]), 0.0, 1e-12);
  }
}

TEST(LoopSurfaceTest, BinaryPlyFileRefines) {
  absl::StatusOr<ControlMesh> mesh =
      ParseControlMeshAuto(ReadMeshTestData("icosahedron_binary_be.ply"), "icosahedron_binary_be.ply");
  ASSERT_TRUE(mesh.ok()) << mesh.status();
  std::unique_ptr<LoopSurface> surface = MustCreate(*mesh, 2);
  ASSERT_NE(surface, nullptr);
  EXPECT_EQ(surface->finest().triangles.size(), 320u);
}

}  // namespace
}  // namespace surfmap
