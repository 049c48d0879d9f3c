// The closest point of a triangle to a point: the one primitive the mesh
// module's BVH (server/mesh) and the haptic renderer's grid (server/haptics)
// both query, kept here so that neither copies it and the renderer need not
// link the mesh module (OpenSubdiv).
#pragma once

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

}  // namespace surfmap
