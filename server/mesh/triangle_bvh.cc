#include "server/mesh/triangle_bvh.h"

#include <algorithm>
#include <limits>

namespace surfmap {
namespace {

constexpr int kLeafSize = 4;
// Depth of a median-split tree over < 2^31 triangles stays far below this.
constexpr int kMaxStack = 96;

double SquaredDistanceToBox(const Eigen::Vector3d& p, const Eigen::Vector3d& lo, const Eigen::Vector3d& hi) {
  const Eigen::Vector3d d = (lo - p).cwiseMax(p - hi).cwiseMax(0.0);
  return d.squaredNorm();
}

}  // namespace

// Ericson, Real-Time Collision Detection, 5.1.5: Voronoi regions of the
// triangle's vertices, edges and face.
ClosestTriangle ClosestPointOnTriangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                                       const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  ClosestTriangle out;
  auto finish = [&](double wa, double wb, double wc) {
    out.barycentric = Eigen::Vector3d(wa, wb, wc);
    out.position = wa * a + wb * b + wc * c;
    out.squared_distance = (p - out.position).squaredNorm();
    return out;
  };
  const Eigen::Vector3d ab = b - a;
  const Eigen::Vector3d ac = c - a;
  const Eigen::Vector3d ap = p - a;
  const double d1 = ab.dot(ap);
  const double d2 = ac.dot(ap);
  if (d1 <= 0.0 && d2 <= 0.0) return finish(1, 0, 0);
  const Eigen::Vector3d bp = p - b;
  const double d3 = ab.dot(bp);
  const double d4 = ac.dot(bp);
  if (d3 >= 0.0 && d4 <= d3) return finish(0, 1, 0);
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) {
    const double v = d1 / (d1 - d3);
    return finish(1 - v, v, 0);
  }
  const Eigen::Vector3d cp = p - c;
  const double d5 = ab.dot(cp);
  const double d6 = ac.dot(cp);
  if (d6 >= 0.0 && d5 <= d6) return finish(0, 0, 1);
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) {
    const double w = d2 / (d2 - d6);
    return finish(1 - w, 0, w);
  }
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0) {
    const double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    return finish(0, 1 - w, w);
  }
  const double denom = 1.0 / (va + vb + vc);
  const double v = vb * denom;
  const double w = vc * denom;
  return finish(1 - v - w, v, w);
}

TriangleBvh::TriangleBvh(const std::vector<Eigen::Vector3d>& positions,
                         const std::vector<std::array<int, 3>>& triangles) {
  const int n = static_cast<int>(triangles.size());
  if (n == 0) return;
  order_.resize(n);
  std::vector<Eigen::Vector3d> centroids(n);
  for (int t = 0; t < n; ++t) {
    order_[t] = t;
    centroids[t] = (positions[triangles[t][0]] + positions[triangles[t][1]] + positions[triangles[t][2]]) / 3.0;
  }
  corners_.resize(n);
  for (int t = 0; t < n; ++t) {
    corners_[t] = {positions[triangles[t][0]], positions[triangles[t][1]], positions[triangles[t][2]]};
  }
  nodes_.reserve(2 * (n / kLeafSize + 1));
  Build(0, n, centroids);
  // Reorder the corners to leaf order so a leaf's triangles are contiguous.
  std::vector<Corners> ordered(n);
  for (int i = 0; i < n; ++i) ordered[i] = corners_[order_[i]];
  corners_ = std::move(ordered);
}

int TriangleBvh::Build(int begin, int end, std::vector<Eigen::Vector3d>& centroids) {
  const int index = static_cast<int>(nodes_.size());
  nodes_.emplace_back();
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d hi = -lo;
  Eigen::Vector3d centroid_lo = lo;
  Eigen::Vector3d centroid_hi = hi;
  for (int i = begin; i < end; ++i) {
    const Corners& c = corners_[order_[i]];
    lo = lo.cwiseMin(c.a).cwiseMin(c.b).cwiseMin(c.c);
    hi = hi.cwiseMax(c.a).cwiseMax(c.b).cwiseMax(c.c);
    centroid_lo = centroid_lo.cwiseMin(centroids[order_[i]]);
    centroid_hi = centroid_hi.cwiseMax(centroids[order_[i]]);
  }
  nodes_[index].lo = lo;
  nodes_[index].hi = hi;
  if (end - begin <= kLeafSize) {
    nodes_[index].first = begin;
    nodes_[index].count = end - begin;
    return index;
  }
  int axis = 0;
  (centroid_hi - centroid_lo).maxCoeff(&axis);
  const int middle = begin + (end - begin) / 2;
  std::nth_element(order_.begin() + begin, order_.begin() + middle, order_.begin() + end,
                   [&](int x, int y) { return centroids[x][axis] < centroids[y][axis]; });
  Build(begin, middle, centroids);
  const int right = Build(middle, end, centroids);
  nodes_[index].first = right;
  nodes_[index].count = 0;
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
    const Node& node = nodes_[stack[--top]];
    if (SquaredDistanceToBox(query, node.lo, node.hi) >= best.squared_distance) continue;
    if (node.count > 0) {
      for (int i = node.first; i < node.first + node.count; ++i) {
        const Corners& c = corners_[i];
        ClosestTriangle candidate = ClosestPointOnTriangle(query, c.a, c.b, c.c);
        if (candidate.squared_distance < best.squared_distance) {
          candidate.triangle = order_[i];
          best = candidate;
        }
      }
      continue;
    }
    const int left = static_cast<int>(&node - nodes_.data()) + 1;
    const int right = node.first;
    const double d_left = SquaredDistanceToBox(query, nodes_[left].lo, nodes_[left].hi);
    const double d_right = SquaredDistanceToBox(query, nodes_[right].lo, nodes_[right].hi);
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

}  // namespace surfmap
