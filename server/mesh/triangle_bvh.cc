#include "server/mesh/triangle_bvh.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace surfmap {
namespace {

constexpr int kLeafSize = 6;
// Depth of a median-split tree over < 2^31 triangles stays far below this.
constexpr int kMaxStack = 96;

// Float box bounds that contain the double value.
float RoundDown(double x) {
  float f = static_cast<float>(x);
  if (static_cast<double>(f) > x) f = std::nextafter(f, -INFINITY);
  return f;
}
float RoundUp(double x) {
  float f = static_cast<float>(x);
  if (static_cast<double>(f) < x) f = std::nextafter(f, INFINITY);
  return f;
}

}  // namespace

TriangleBvh::TriangleBvh(const std::vector<Eigen::Vector3d>* positions,
                         const std::vector<std::array<int, 3>>* triangles)
    : positions_(positions), triangles_(triangles) {
  const int n = static_cast<int>(triangles->size());
  if (n == 0) return;
  std::vector<BuildItem> items(n);
  for (int t = 0; t < n; ++t) {
    const auto& tri = (*triangles)[t];
    const Eigen::Vector3d c = ((*positions)[tri[0]] + (*positions)[tri[1]] + (*positions)[tri[2]]) / 3.0;
    items[t] = {{static_cast<float>(c.x()), static_cast<float>(c.y()), static_cast<float>(c.z())}, t};
  }
  nodes_.reserve(2 * (n / kLeafSize + 1));
  Build(items, 0, n);
  order_.resize(n);
  for (int i = 0; i < n; ++i) order_[i] = items[i].triangle;
}

int TriangleBvh::Build(std::vector<BuildItem>& items, int begin, int end) {
  const int index = static_cast<int>(nodes_.size());
  nodes_.emplace_back();
  if (end - begin <= kLeafSize) {
    Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
    Eigen::Vector3d hi = -lo;
    for (int i = begin; i < end; ++i) {
      for (int corner : (*triangles_)[items[i].triangle]) {
        lo = lo.cwiseMin((*positions_)[corner]);
        hi = hi.cwiseMax((*positions_)[corner]);
      }
    }
    Node& node = nodes_[index];
    for (int a = 0; a < 3; ++a) {
      node.lo[a] = RoundDown(lo[a]);
      node.hi[a] = RoundUp(hi[a]);
    }
    node.first = begin;
    node.count = end - begin;
    return index;
  }
  float centroid_lo[3] = {INFINITY, INFINITY, INFINITY};
  float centroid_hi[3] = {-INFINITY, -INFINITY, -INFINITY};
  for (int i = begin; i < end; ++i) {
    for (int a = 0; a < 3; ++a) {
      centroid_lo[a] = std::min(centroid_lo[a], items[i].centroid[a]);
      centroid_hi[a] = std::max(centroid_hi[a], items[i].centroid[a]);
    }
  }
  int axis = 0;
  for (int a = 1; a < 3; ++a) {
    if (centroid_hi[a] - centroid_lo[a] > centroid_hi[axis] - centroid_lo[axis]) axis = a;
  }
  const int middle = begin + (end - begin) / 2;
  std::nth_element(items.begin() + begin, items.begin() + middle, items.begin() + end,
                   [axis](const BuildItem& x, const BuildItem& y) { return x.centroid[axis] < y.centroid[axis]; });
  const int left = Build(items, begin, middle);
  const int right = Build(items, middle, end);
  Node& node = nodes_[index];
  for (int a = 0; a < 3; ++a) {
    node.lo[a] = std::min(nodes_[left].lo[a], nodes_[right].lo[a]);
    node.hi[a] = std::max(nodes_[left].hi[a], nodes_[right].hi[a]);
  }
  node.first = right;
  node.count = 0;
  return index;
}

ClosestTriangle TriangleBvh::Closest(const Eigen::Vector3d& query) const {
  ClosestTriangle best;
  if (nodes_.empty()) return best;
  best.squared_distance = std::numeric_limits<double>::infinity();
  int stack[kMaxStack];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const int index = stack[--top];
    const Node& node = nodes_[index];
    if (SquaredDistanceToBox(query, node) >= best.squared_distance) continue;
    if (node.count > 0) {
      for (int i = node.first; i < node.first + node.count; ++i) {
        const auto& tri = (*triangles_)[order_[i]];
        ClosestTriangle candidate =
            ClosestPointOnTriangle(query, (*positions_)[tri[0]], (*positions_)[tri[1]], (*positions_)[tri[2]]);
        if (candidate.squared_distance < best.squared_distance) {
          candidate.triangle = order_[i];
          best = candidate;
        }
      }
      continue;
    }
    const int left = index + 1;
    const int right = node.first;
    const double d_left = SquaredDistanceToBox(query, nodes_[left]);
    const double d_right = SquaredDistanceToBox(query, nodes_[right]);
    // Visit the nearer child first (pushed last) so the bound tightens early.
    if (d_left < d_right) {
      if (d_right < best.squared_distance) stack[top++] = right;
      if (d_left < best.squared_distance) stack[top++] = left;
    } else {
      if (d_left < best.squared_distance) stack[top++] = left;
      if (d_right < best.squared_distance) stack[top++] = right;
    }
  }
  return best;
}

double TriangleBvh::SquaredDistanceToBox(const Eigen::Vector3d& p, const Node& node) {
  double sum = 0.0;
  for (int a = 0; a < 3; ++a) {
    const double below = static_cast<double>(node.lo[a]) - p[a];
    const double above = p[a] - static_cast<double>(node.hi[a]);
    const double d = std::max({below, above, 0.0});
    sum += d * d;
  }
  return sum;
}

}  // namespace surfmap
