// Test helper (header-only, not part of the library): a flat rectangular plate
// triangulated as a regular grid and refined by midpoint subdivision into a
// hierarchy of SurfaceLevels that follows LoopSurface's vertex numbering
// contract (vertex i of level k is vertex i of every finer level; the vertex
// splitting edge e of level k is vertex nv_k + e of level k+1).
//
// On a flat plate the Loop limit surface is the plate itself, so limit
// positions are the refined positions and every normal is +z. This lets the
// planner and the map be tested without OpenSubdiv.
#pragma once

#include <algorithm>
#include <array>
#include <map>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include "server/mesh/loop_surface.h"

namespace surfmap::testing {

inline void FillEdgesAndNeighbors(SurfaceLevel& level) {
  const int nv = static_cast<int>(level.positions.size());
  std::vector<std::array<int, 2>> edges;
  for (const auto& t : level.triangles) {
    for (int i = 0; i < 3; ++i) {
      int a = t[i], b = t[(i + 1) % 3];
      edges.push_back({std::min(a, b), std::max(a, b)});
    }
  }
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  level.edges = edges;
  level.neighbors.assign(nv, {});
  for (const auto& e : edges) {
    level.neighbors[e[0]].push_back(e[1]);
    level.neighbors[e[1]].push_back(e[0]);
  }
  for (auto& n : level.neighbors) std::sort(n.begin(), n.end());
}

// A plate [x0, x0 + nx*h] x [y0, y0 + ny*h] at z = 0, each grid cell split
// along its (0,0)-(1,1) diagonal, counter-clockwise seen from +z.
inline SurfaceLevel MakeFlatGrid(int nx, int ny, double h, double x0 = 0.0, double y0 = 0.0) {
  SurfaceLevel level;
  auto id = [nx](int i, int j) { return j * (nx + 1) + i; };
  for (int j = 0; j <= ny; ++j) {
    for (int i = 0; i <= nx; ++i) level.positions.emplace_back(x0 + i * h, y0 + j * h, 0.0);
  }
  for (int j = 0; j < ny; ++j) {
    for (int i = 0; i < nx; ++i) {
      level.triangles.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      level.triangles.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  }
  level.limit_positions = level.positions;
  level.limit_normals.assign(level.positions.size(), Eigen::Vector3d::UnitZ());
  FillEdgesAndNeighbors(level);
  return level;
}

// MakeFlatGrid(nx, ny, 1 mm) with the corner (nx - 5, 1) moved onto the
// plate's bottom edge, 1e-150 mm above the middle of the cell edge from
// (nx - 6, 0) to (nx - 5, 0): the triangle it makes with them is a sliver
// whose cotangents are ~1e150, and its other triangles fold over their
// neighbours, as a fine level moved onto a bumpy scan does (dense_surface.h;
// the scan test's pebble had cotangents of 1.8e299).
inline SurfaceLevel MakeFlatGridWithSliver(int nx, int ny) {
  SurfaceLevel level = MakeFlatGrid(nx, ny, 1.0);
  const int moved = 1 * (nx + 1) + (nx - 5);
  level.limit_positions[moved] = Eigen::Vector3d(nx - 5.5, 1e-150, 0.0);
  level.positions[moved] = level.limit_positions[moved];
  return level;
}

// Midpoint (1-to-4) refinement of `coarse`; fills coarse.edge_child_vertex
// and the child's parent_edge.
inline SurfaceLevel RefineMidpoint(SurfaceLevel& coarse) {
  const int nv = static_cast<int>(coarse.positions.size());
  std::map<std::pair<int, int>, int> edge_index;
  for (int e = 0; e < static_cast<int>(coarse.edges.size()); ++e) {
    edge_index[{coarse.edges[e][0], coarse.edges[e][1]}] = e;
  }
  SurfaceLevel fine;
  fine.positions = coarse.positions;
  fine.parent_edge.assign(nv, -1);
  coarse.edge_child_vertex.resize(coarse.edges.size());
  for (int e = 0; e < static_cast<int>(coarse.edges.size()); ++e) {
    const auto& [a, b] = coarse.edges[e];
    fine.positions.push_back(0.5 * (coarse.positions[a] + coarse.positions[b]));
    fine.parent_edge.push_back(e);
    coarse.edge_child_vertex[e] = nv + e;
  }
  auto mid = [&](int a, int b) { return nv + edge_index.at({std::min(a, b), std::max(a, b)}); };
  for (const auto& t : coarse.triangles) {
    int a = t[0], b = t[1], c = t[2];
    int ab = mid(a, b), bc = mid(b, c), ca = mid(c, a);
    fine.triangles.push_back({a, ab, ca});
    fine.triangles.push_back({ab, b, bc});
    fine.triangles.push_back({ca, bc, c});
    fine.triangles.push_back({ab, bc, ca});
  }
  fine.limit_positions = fine.positions;
  fine.limit_normals.assign(fine.positions.size(), Eigen::Vector3d::UnitZ());
  FillEdgesAndNeighbors(fine);
  return fine;
}

// Levels 0..max_level of a refined flat grid.
inline std::vector<SurfaceLevel> MakeFlatGridLevels(int nx, int ny, double h, int max_level, double x0 = 0.0,
                                                    double y0 = 0.0) {
  std::vector<SurfaceLevel> levels;
  levels.push_back(MakeFlatGrid(nx, ny, h, x0, y0));
  for (int k = 0; k < max_level; ++k) levels.push_back(RefineMidpoint(levels.back()));
  return levels;
}

inline std::vector<const SurfaceLevel*> Pointers(const std::vector<SurfaceLevel>& levels) {
  std::vector<const SurfaceLevel*> out;
  for (const auto& l : levels) out.push_back(&l);
  return out;
}

}  // namespace surfmap::testing
