// SurfaceLocator: the exact closest point on a triangle mesh for a haptic
// loop. A uniform grid of cells holds the triangles whose bounding boxes
// overlap each cell; a query first measures the triangle of the previous
// query (a probe moves a fraction of a millimetre per sample, so that is
// almost always the answer or next to it), then visits only the cells nearer
// than that distance, shell by shell. The answer is exact (the same triangle
// distance a brute-force search finds); the hint only makes it fast.
//
// A grid rather than the mesh module's BVH: the renderer library does not
// depend on OpenSubdiv, and the grid accepts an initial bound, so a coherent
// query touches one or two cells instead of descending the tree.
//
// Closest() allocates nothing and is const: several probes may share one
// locator, each with its own hint.
#pragma once

#include <array>
#include <vector>

#include <Eigen/Core>
#include "server/geometry/closest_point.h"

namespace surfmap::haptics {

// A surface lookup's answer: the closest triangle, its barycentrics and point.
using TriangleHit = ::surfmap::ClosestTriangle;
using ::surfmap::ClosestPointOnTriangle;

class SurfaceLocator {
 public:
  SurfaceLocator() = default;
  // Copies the mesh. Triangle indices must be valid (callers validate).
  SurfaceLocator(std::vector<Eigen::Vector3d> positions, std::vector<std::array<int, 3>> triangles);

  // The closest point over all triangles. `hint` is a triangle to measure
  // first (the previous answer), or -1. Triangle -1 for an empty mesh.
  TriangleHit Closest(const Eigen::Vector3d& query, int hint = -1) const;

  // Number of triangle distance evaluations of the last Closest() on this
  // thread (for tests of the coherence claim).
  static int LastTrianglesTested();

  double cell_size_mm() const { return cell_; }
  std::array<int, 3> grid_size() const { return dims_; }

 private:
  int CellIndex(int i, int j, int k) const { return (k * dims_[1] + j) * dims_[0] + i; }
  double SquaredDistanceToCell(const Eigen::Vector3d& p, int i, int j, int k) const;

  std::vector<Eigen::Vector3d> positions_;
  std::vector<std::array<int, 3>> triangles_;
  Eigen::Vector3d origin_ = Eigen::Vector3d::Zero();
  double cell_ = 1.0;
  std::array<int, 3> dims_ = {0, 0, 0};
  std::vector<int> cell_start_;      // CSR: triangles of cell c are cell_triangles_[cell_start_[c] .. cell_start_[c+1])
  std::vector<int> cell_triangles_;
};

}  // namespace surfmap::haptics
