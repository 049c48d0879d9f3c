// Internal to the mesh module: a bounding-volume hierarchy over a triangle
// mesh for exact closest-point queries (median split, axis-aligned boxes).
#pragma once

#include <array>
#include <vector>

#include <Eigen/Core>
#include "server/geometry/closest_point.h"

namespace surfmap {

class TriangleBvh {
 public:
  TriangleBvh() = default;
  // Keeps pointers to `positions` and `triangles`: both must outlive the tree
  // unchanged. (The tree is built over the finest level that owns them; not
  // copying them saves ~70 bytes per triangle.)
  TriangleBvh(const std::vector<Eigen::Vector3d>* positions, const std::vector<std::array<int, 3>>* triangles);

  // The exact closest point over all triangles; triangle -1 for an empty tree.
  ClosestTriangle Closest(const Eigen::Vector3d& query) const;

  int num_nodes() const { return static_cast<int>(nodes_.size()); }

 private:
  // 32 bytes. Float boxes rounded outward, so pruning stays exact.
  struct Node {
    float lo[3], hi[3];
    int first = 0;  // leaf: first entry of order_; inner: index of the right child (left is this + 1)
    int count = 0;  // leaf: number of triangles; inner: 0
  };
  struct BuildItem {
    float centroid[3];
    int triangle;
  };

  int Build(std::vector<BuildItem>& items, int begin, int end);
  static double SquaredDistanceToBox(const Eigen::Vector3d& p, const Node& node);

  const std::vector<Eigen::Vector3d>* positions_ = nullptr;
  const std::vector<std::array<int, 3>>* triangles_ = nullptr;
  std::vector<Node> nodes_;
  std::vector<int> order_;  // triangle ids, grouped by leaf
};

}  // namespace surfmap
