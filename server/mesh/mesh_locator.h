// Closest points on any triangle mesh (a surface level other than the
// LoopSurface's finest, or a map's mesh read back from a file): the exact
// closest point over its triangles, found with the module's bounding-volume
// tree (triangle_bvh.h).
#pragma once

#include <array>
#include <memory>
#include <vector>

#include <Eigen/Core>
#include "server/mesh/loop_surface.h"

namespace surfmap {

class MeshLocator {
 public:
  // Copies the mesh. Triangle indices must lie in 0..positions.size()-1
  // (callers validate); an empty mesh finds nothing.
  MeshLocator(std::vector<Eigen::Vector3d> positions, std::vector<std::array<int, 3>> triangles);
  // The limit mesh of a surface level.
  explicit MeshLocator(const SurfaceLevel& level);
  MeshLocator(MeshLocator&&) noexcept;
  MeshLocator& operator=(MeshLocator&&) noexcept;
  ~MeshLocator();

  // The closest point: triangle (-1 for an empty mesh), barycentric weights
  // of its vertices, position, distance; normal = the triangle's unit normal
  // (by its winding).
  SurfacePoint Closest(const Eigen::Vector3d& query) const;
  // Where the line through `point` along unit `direction` meets the surface
  // near it: the closest point of the point on the line that is its own
  // closest point's foot (found by moving there until it stops, within
  // 1e-4 mm), if that closest point lies on the line (within 0.05 mm);
  // else triangle -1. A point of a tangent plane carried onto a curved
  // surface along the plane's normal (boundary_rectangles.h).
  SurfacePoint ClosestAlong(const Eigen::Vector3d& point, const Eigen::Vector3d& direction) const;

  const std::vector<Eigen::Vector3d>& positions() const;
  const std::vector<std::array<int, 3>>& triangles() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace surfmap
