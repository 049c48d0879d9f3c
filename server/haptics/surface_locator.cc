#include "server/haptics/surface_locator.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace surfmap::haptics {
namespace {

// Triangles per occupied cell the grid aims at: a few, so that a query that
// stays in its cell tests a handful of triangles.
constexpr double kEdgesPerCell = 2.0;
// Memory guard: at most this many cells per triangle.
constexpr double kMaxCellsPerTriangle = 8.0;

thread_local int tested_count = 0;

}  // namespace

SurfaceLocator::SurfaceLocator(std::vector<Eigen::Vector3d> positions, std::vector<std::array<int, 3>> triangles)
    : positions_(std::move(positions)), triangles_(std::move(triangles)) {
  if (triangles_.empty()) return;
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d hi = -lo;
  double edge_sum = 0.0;
  for (const auto& t : triangles_) {
    for (int c = 0; c < 3; ++c) {
      lo = lo.cwiseMin(positions_[t[c]]);
      hi = hi.cwiseMax(positions_[t[c]]);
      edge_sum += (positions_[t[c]] - positions_[t[(c + 1) % 3]]).norm();
    }
  }
  const double ntri = static_cast<double>(triangles_.size());
  const Eigen::Vector3d extent = (hi - lo).cwiseMax(1e-9);
  cell_ = std::max(kEdgesPerCell * edge_sum / (3.0 * ntri), 1e-6);
  // Coarsen until the grid holds at most kMaxCellsPerTriangle cells per triangle.
  for (;;) {
    double cells = 1.0;
    for (int a = 0; a < 3; ++a) cells *= std::floor(extent[a] / cell_) + 1.0;
    if (cells <= kMaxCellsPerTriangle * ntri + 64) break;
    cell_ *= 1.25;
  }
  origin_ = lo;
  for (int a = 0; a < 3; ++a) dims_[a] = static_cast<int>(std::floor(extent[a] / cell_)) + 1;

  auto cell_range = [&](const std::array<int, 3>& t, std::array<int, 3>& from, std::array<int, 3>& to) {
    for (int a = 0; a < 3; ++a) {
      double mn = std::min({positions_[t[0]][a], positions_[t[1]][a], positions_[t[2]][a]});
      double mx = std::max({positions_[t[0]][a], positions_[t[1]][a], positions_[t[2]][a]});
      from[a] = std::clamp(static_cast<int>(std::floor((mn - origin_[a]) / cell_)), 0, dims_[a] - 1);
      to[a] = std::clamp(static_cast<int>(std::floor((mx - origin_[a]) / cell_)), 0, dims_[a] - 1);
    }
  };
  const size_t ncells = static_cast<size_t>(dims_[0]) * dims_[1] * dims_[2];
  cell_start_.assign(ncells + 1, 0);
  std::array<int, 3> from{}, to{};
  for (const auto& t : triangles_) {  // count
    cell_range(t, from, to);
    for (int k = from[2]; k <= to[2]; ++k)
      for (int j = from[1]; j <= to[1]; ++j)
        for (int i = from[0]; i <= to[0]; ++i) ++cell_start_[CellIndex(i, j, k) + 1];
  }
  for (size_t c = 0; c < ncells; ++c) cell_start_[c + 1] += cell_start_[c];
  cell_triangles_.resize(cell_start_[ncells]);
  std::vector<int> fill(cell_start_.begin(), cell_start_.end() - 1);
  for (int ti = 0; ti < static_cast<int>(triangles_.size()); ++ti) {  // place
    cell_range(triangles_[ti], from, to);
    for (int k = from[2]; k <= to[2]; ++k)
      for (int j = from[1]; j <= to[1]; ++j)
        for (int i = from[0]; i <= to[0]; ++i) cell_triangles_[fill[CellIndex(i, j, k)]++] = ti;
  }
}

double SurfaceLocator::SquaredDistanceToCell(const Eigen::Vector3d& p, int i, int j, int k) const {
  const int idx[3] = {i, j, k};
  double d2 = 0.0;
  for (int a = 0; a < 3; ++a) {
    const double lo = origin_[a] + idx[a] * cell_;
    const double hi = lo + cell_;
    const double d = p[a] < lo ? lo - p[a] : (p[a] > hi ? p[a] - hi : 0.0);
    d2 += d * d;
  }
  return d2;
}

int SurfaceLocator::LastTrianglesTested() { return tested_count; }

TriangleHit SurfaceLocator::Closest(const Eigen::Vector3d& query, int hint) const {
  TriangleHit best;
  tested_count = 0;
  if (triangles_.empty()) return best;
  best.squared_distance = std::numeric_limits<double>::infinity();
  auto test = [&](int ti) {
    ++tested_count;
    const auto& t = triangles_[ti];
    TriangleHit hit = ClosestPointOnTriangle(query, positions_[t[0]], positions_[t[1]], positions_[t[2]]);
    if (hit.squared_distance < best.squared_distance) {
      hit.triangle = ti;
      best = hit;
    }
  };
  if (hint >= 0 && hint < static_cast<int>(triangles_.size())) test(hint);

  int c0[3];
  for (int a = 0; a < 3; ++a) {
    c0[a] = std::clamp(static_cast<int>(std::floor((query[a] - origin_[a]) / cell_)), 0, dims_[a] - 1);
  }
  const int max_ring = std::max({dims_[0], dims_[1], dims_[2]});
  for (int r = 0; r <= max_ring; ++r) {
    // Every cell of shell r is at least (r - 1) cells away from the query along
    // some axis (also for a query outside the grid, which is clamped to its
    // nearest cell): nothing closer can lie at or beyond this shell.
    const double lower = std::max(0, r - 1) * cell_;
    if (lower * lower >= best.squared_distance) break;
    const int k0 = std::max(c0[2] - r, 0), k1 = std::min(c0[2] + r, dims_[2] - 1);
    const int j0 = std::max(c0[1] - r, 0), j1 = std::min(c0[1] + r, dims_[1] - 1);
    const int i0 = std::max(c0[0] - r, 0), i1 = std::min(c0[0] + r, dims_[0] - 1);
    for (int k = k0; k <= k1; ++k) {
      for (int j = j0; j <= j1; ++j) {
        const bool inner_jk = std::abs(k - c0[2]) < r && std::abs(j - c0[1]) < r;
        for (int i = i0; i <= i1; ++i) {
          // Only the shell: interior cells were visited in earlier rings. On
          // an inner row, jump straight from the left face to the right one.
          if (inner_jk && std::abs(i - c0[0]) < r) {
            i = c0[0] + r - 1;
            continue;
          }
          if (SquaredDistanceToCell(query, i, j, k) >= best.squared_distance) continue;
          const int c = CellIndex(i, j, k);
          for (int e = cell_start_[c]; e < cell_start_[c + 1]; ++e) {
            if (cell_triangles_[e] != best.triangle) test(cell_triangles_[e]);
          }
        }
      }
    }
  }
  return best;
}

}  // namespace surfmap::haptics
