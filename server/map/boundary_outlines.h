// What round dots (boundary_dots.h) and small rectangles
// (boundary_rectangles.h) share: a closed outline drawn through the
// crossings of one region's edge, as chords, in place of the links between
// those crossings.
#pragma once

#include <optional>
#include <vector>

#include <Eigen/Core>
#include "server/map/boundary_corridor.h"
#include "server/map/boundary_links.h"

namespace surfmap {

struct BoundaryOutline {
  std::vector<int> marks;  // the crossings of its edge
  int inner = -1;          // the enclosed region
  int outer = -1;          // the region outside (of most chords)
  std::vector<BoundarySegment> chords;  // its edge, a = inner (inwards)
  // Nonzero: the plane normal the outline was drawn in. Its chords lie in
  // that plane, off a curved surface, and their seeds belong where the
  // normal through them meets the surface, not at the nearest point.
  Eigen::Vector3d project_along = Eigen::Vector3d::Zero();
};

// A plane through `origin` with unit normal `normal` and in-plane basis
// e1, e2: where an outline is fitted.
struct MarksPlane {
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
  Eigen::Vector3d e1 = Eigen::Vector3d::UnitX(), e2 = Eigen::Vector3d::UnitY();
  Eigen::Vector2d At(const Eigen::Vector3d& p) const { return {(p - origin).dot(e1), (p - origin).dot(e2)}; }
  double Off(const Eigen::Vector3d& p) const { return (p - origin).dot(normal); }
  Eigen::Vector3d Point(const Eigen::Vector2d& q) const { return origin + q.x() * e1 + q.y() * e2; }
  Eigen::Vector3d Vector(const Eigen::Vector2d& d) const { return d.x() * e1 + d.y() * e2; }
};

// The plane of the group's mean normal through its centroid, if every
// mark's normal lies within options.max_corner_normal_deg of the mean (the
// marks lie on one piece of surface).
std::optional<MarksPlane> PlaneOfMarks(const std::vector<ChangeMark>& marks, const std::vector<int>& group,
                                       const BoundaryLinkOptions& options);

// Groups of marks (indices into `members`) within `reach` of each other,
// chained (single linkage).
std::vector<std::vector<int>> GroupMarks(const std::vector<ChangeMark>& marks, const std::vector<int>& members,
                                         double reach);

// The marks by region: every mark between two regions is listed under both.
std::vector<std::pair<int, std::vector<int>>> MarksByRegion(const std::vector<ChangeMark>& marks);

// The region on the other side of mark m from `region`.
inline int OtherRegion(const ChangeMark& m, int region) { return m.before == region ? m.after : m.before; }

// `chords` less those `contradicted` flags, or nothing when more than
// options.max_dot_contradicted_chord_share of them are.
std::optional<std::vector<BoundarySegment>> UncontradictedChords(std::vector<BoundarySegment> chords,
                                                                 const std::vector<bool>& contradicted,
                                                                 const BoundaryLinkOptions& options);

}  // namespace surfmap
