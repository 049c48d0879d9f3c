// Internal to the mesh module: a bounding-volume hierarchy over a triangle
// mesh for closest-point queries (median split, axis-aligned boxes).
#pragma once

#include <array>
#include <vector>

#include <Eigen/Core>

namespace surfmap {

struct ClosestTriangle {
  int triangle = -1;
  Eigen::Vector3d barycentric = Eigen::Vector3d::Zero();  // weights of the triangle's vertices 0, 1, 2
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  double squared_distance = 0.0;
};

// The closest point of triangle (a, b, c) to p, with its barycentrics.
// Points in an edge or vertex region get exact zeros in the other weights.
ClosestTriangle ClosestPointOnTriangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                                       const Eigen::Vector3d& b, const Eigen::Vector3d& c);

class TriangleBvh {
 public:
  TriangleBvh() = default;
  // Copies what it needs; the inputs may go away. Triangles index `positions`.
  TriangleBvh(const std::vector<Eigen::Vector3d>& positions, const std::vector<std::array<int, 3>>& triangles);

  // The closest point over all triangles (exact, not approximate). Triangle
  // -1 for an empty tree.
  ClosestTriangle Closest(const Eigen::Vector3d& query) const;

  int num_nodes() const { return static_cast<int>(nodes_.size()); }

 private:
  struct Node {
    Eigen::Vector3d lo, hi;
    int first = 0;  // leaf: first entry of order_; inner: index of the right child (left is this + 1)
    int count = 0;  // leaf: number of triangles; inner: 0
  };
  struct Corners {
    Eigen::Vector3d a, b, c;
  };

  int Build(int begin, int end, std::vector<Eigen::Vector3d>& centroids);

  std::vector<Node> nodes_;
  std::vector<int> order_;        // triangle ids, grouped by leaf
  std::vector<Corners> corners_;  // in order_ order, for cache-friendly leaves
};

}  // namespace surfmap
