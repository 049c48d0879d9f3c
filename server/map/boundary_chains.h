// Chains of links (boundary_links.h): crossings of one boundary joined one
// after another. A chain's end is a crossing with a link on one side only;
// the boundary there runs on, to first order, along its last link.
#pragma once

#include <optional>
#include <vector>

#include <Eigen/Core>
#include "server/map/boundary_links.h"

namespace surfmap {

// A link drawn between marks[from] and marks[to]: regions a < b, a on the
// side of towards_a.
struct DrawnLink {
  int from = -1;
  int to = -1;
  int a = -1;
  int b = -1;
  Eigen::Vector3d towards_a = Eigen::Vector3d::Zero();
};

struct ChainEnd {
  int mark = -1;
  Eigen::Vector3d out = Eigen::Vector3d::Zero();  // unit, out of the chain along its last link
  Eigen::Vector3d towards_a = Eigen::Vector3d::Zero();
  int a = -1;
  int b = -1;
};

// v's component in the plane with unit normal n.
inline Eigen::Vector3d InPlane(const Eigen::Vector3d& v, const Eigen::Vector3d& n) { return v - v.dot(n) * n; }

// Unit vector pointing to region `a`'s side at a mark, in its tangent plane.
inline Eigen::Vector3d TowardsA(const ChangeMark& m, int a) {
  return m.before == a ? Eigen::Vector3d(-m.direction) : m.direction;
}

// The unit vector across the chord p -> q (in the plane of their mean
// normal) towards region a's side, when a lies on the same side at both and
// both drags ran within acos(min_cos) of perpendicular to the chord;
// nullopt otherwise.
std::optional<Eigen::Vector3d> AcrossChordTowardsA(const ChangeMark& p, const ChangeMark& q, int a, double min_cos);

// The ends of the chains `links` make. An end's direction is its last
// link's when that is at least min_link_mm long (a shorter one's is too
// uncertain to carry on). Otherwise, with reach_past_short_links, it runs
// from the first mark back along the chain at least min_link_mm from the
// end (through marks with two links only); without it, or when the chain
// branches or stops before, the end is skipped.
std::vector<ChainEnd> ChainEnds(const std::vector<ChangeMark>& marks, const std::vector<DrawnLink>& links,
                                double min_link_mm, bool reach_past_short_links);

}  // namespace surfmap
