// The checks and seeds shared by every boundary drawn between crossings
// (boundary_links.h: straight links; boundary_corners.h: corners): a
// segment of boundary is drawn only where no data contradicts it, and it
// becomes labelled points just either side of it.
#pragma once

#include <cstdint>
#include <unordered_map>
#include <vector>

#include <Eigen/Core>
#include "server/map/boundary_links.h"

namespace surfmap {

// Labelled points by cell of a 3D grid, for the queries near a segment or a
// point that boundaries (corridor checks here) and the region map (the
// nearest data point, region_map.h) make. Owns its points, so it can be
// copied with its owner.
class LabelledPointGrid {
 public:
  LabelledPointGrid() = default;  // empty: no point is near anything
  LabelledPointGrid(std::vector<LabelledPoint> points, double cell);
  bool empty() const { return points_.empty(); }
  // Calls fn(point) for every point in the cells of the box around a and b
  // grown by `margin` (a superset of the points within margin of a..b).
  template <typename Fn>
  void ForEachNear(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double margin, const Fn& fn) const {
    if (points_.empty()) return;
    const Eigen::Vector3i lo = Cell(a.cwiseMin(b) - Eigen::Vector3d::Constant(margin));
    const Eigen::Vector3i hi = Cell(a.cwiseMax(b) + Eigen::Vector3d::Constant(margin));
    for (int x = lo.x(); x <= hi.x(); ++x) {
      for (int y = lo.y(); y <= hi.y(); ++y) {
        for (int z = lo.z(); z <= hi.z(); ++z) {
          auto it = cells_.find(Key({x, y, z}));
          if (it == cells_.end()) continue;
          for (int i : it->second) fn(points_[i]);
        }
      }
    }
  }

 private:
  Eigen::Vector3i Cell(const Eigen::Vector3d& p) const { return (p / cell_).array().floor().cast<int>().matrix(); }
  static std::uint64_t Key(const Eigen::Vector3i& c);
  std::vector<LabelledPoint> points_;
  double cell_ = 1.0;
  std::unordered_map<std::uint64_t, std::vector<int>> cells_;
};

// A boundary segment p -> q between regions a and b, a on the side of the
// unit vector towards_a (perpendicular to the segment, in the surface).
// The surface between p and q bows off the straight chord: `bow` goes from
// the chord's middle to the surface's (ChordBow; zero on a plane).
struct BoundarySegment {
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
  Eigen::Vector3d q = Eigen::Vector3d::Zero();
  Eigen::Vector3d towards_a = Eigen::Vector3d::Zero();
  int a = -1;
  int b = -1;
  Eigen::Vector3d bow = Eigen::Vector3d::Zero();
};

// The bow of a chord p -> q of a surface whose unit normal turns from n_p to
// n_q, taking the surface between them as a circular arc: a sagitta of
// (|q - p| / 2) tan(theta / 4), theta the angle between the normals, along
// their mean, outwards where they open up along the chord (a convex
// surface) and inwards where they close. A 20 mm chord round a 40 mm radius
// bows 1.27 mm: a drag across its middle passes farther from the chord than
// a corridor's width.
Eigen::Vector3d ChordBow(const Eigen::Vector3d& p, const Eigen::Vector3d& q, const Eigen::Vector3d& n_p,
                         const Eigen::Vector3d& n_q);

// What contradicts a segment, measured from the arc p -> p + bow -> q (a
// parabola, where the surface lies) between its ends: a point of a third
// region within third_region_mm of it, or, within reach_mm of it, a point of
// a more than wrong_side_mm on b's side or of b on a's.
struct CorridorCheck {
  double third_region_mm = 0.0;
  double wrong_side_mm = 0.0;
  double reach_mm = 0.0;
};
bool SegmentContradicted(const BoundarySegment& s, const LabelledPointGrid& data, const CorridorCheck& check);

// A link's check: within options.corridor_mm of the segment, any third region,
// or a or b more than seed_offset_mm on the other's side.
bool SegmentContradicted(const BoundarySegment& s, const LabelledPointGrid& data, const BoundaryLinkOptions& options);

// The segment's labelled points: every seed_spacing_mm along it,
// seed_offset_mm to a's side labelled a and to b's side labelled b.
void AppendSegmentSeeds(const BoundarySegment& s, const BoundaryLinkOptions& options, std::vector<LabelledPoint>* out);

}  // namespace surfmap
