// Corners of boundaries between crossings. Links (boundary_links.h) join
// crossings of a boundary that drags crossed near perpendicular to it, so a
// patch's straight sides become chains of links; at the patch's corner the
// drags run obliquely and no link is drawn. The regions' spreading
// (label_propagation.h) then rounds the corner off between the last
// crossings of the two sides: on the bottle's 40 mm patches half of the
// misclassified points lay within 6 mm of a corner, nearly all of them
// sandpaper cut off as glass.
//
// Two chain ends E1 and E2 of the same two regions (an end: a crossing with
// a link on one side only; its direction: its link's, pointing out of the
// chain) are joined by a corner C where the two boundaries, carried
// straight on, meet:
//  - C lies ahead of both ends, within corner_reach_mm of each;
//  - the boundary turns there by min..max_corner_turn_deg (a straight run
//    on is not a corner; a turn sharper than max is a dot's or a hairpin's,
//    whose straight continuations overshoot it);
//  - the same region lies on the same hand along E1 -> C -> E2;
//  - no data contradicts it: the corridor of each segment as for a link,
//    and inside the triangle E1, C, E2 only the region the corner encloses.
// Each end takes part in at most one corner, the nearest (least s + t, the
// two distances to C) first.
#pragma once

#include <vector>

#include <Eigen/Core>
#include "server/map/boundary_chains.h"
#include "server/map/boundary_corridor.h"
#include "server/map/boundary_links.h"

namespace surfmap {

// The corners' labelled points; *corners (if given) receives how many.
std::vector<LabelledPoint> BoundaryCornerPoints(const std::vector<ChangeMark>& marks,
                                                const std::vector<DrawnLink>& links, const LabelledPointGrid& data,
                                                const BoundaryLinkOptions& options, int* corners = nullptr);

}  // namespace surfmap
