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
//
// A link can cut a corner off too: two crossings, one on each side of a
// patch's corner, are linked when both drags ran near perpendicular to the
// chord between them, and the chord then cuts across the corner (the
// bottle, seed 3: a 14 mm chord between crossings of its patch's top and
// side, 11 and 8 mm from the corner, mapped a triangle of sandpaper as
// glass). A link P-Q is replaced by the corner P -> C -> Q when
//  - the chain on each side of it (its other links, walked from P and from
//    Q) runs straight: at least two links, every mark within
//    corner_side_reach_mm of the end lying within
//    max_corner_side_residual_mm of the line from the end to the farthest
//    of them (in the end's tangent plane). A round boundary's chain turns
//    at every crossing, so a dot or a curved band keeps its chords. A side
//    with one link within the reach is straight when the link after it,
//    past the reach, turns from it by at most max_line_turn_deg
//    (corner_side_checked_past_reach): a side that turns there is a cut
//    corner's link itself, or round. A side of one link whose chain ends
//    there (corner_side_may_end_its_chain) is taken as it runs when the
//    other side is straight by the rules above; two such sides never are,
//    for four crossings are a round arc as well as a corner;
//  - the two sides, carried on along those lines, make a corner by the rule
//    for two chain ends above (ahead of both, within reach, turning by
//    min..max_corner_turn_deg, the same hand);
//  - no data contradicts the corner's two segments or its triangle P, C, Q.
// A small patch's side runs round its next corner within
// corner_side_reach_mm: a side that runs straight over two links or more
// and then turns by min_corner_turn_deg is taken as that straight run
// (corner_side_stops_at_next_corner). Where one side is straight by these
// rules (not a lone link whose chain ends) and the other shows no direction
// (a side crossed once, or whose chain turns at once), the unknown side is
// taken square to the straight one (square_corner_from_one_side): most
// patches a lab maps (tape, labels, sandpaper) have square corners, a chord
// cuts every corner, and the corner's data checks still refuse a square
// corner where a drag saw the other region inside it. On held_vase seed 4
// a drag-sized patch's side crossed at one place had a chord cut 8 % of
// the patch off (docs/method.md, "Square corners").
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

// `links` without those that cut a corner (above); the corners' labelled
// points are appended to *points, and *count (if given) receives how many.
// max_corner_side_residual_mm, corner_reach_mm or corner_side_reach_mm = 0:
// none replaced.
std::vector<DrawnLink> ReplaceCutCorners(const std::vector<ChangeMark>& marks, std::vector<DrawnLink> links,
                                         const LabelledPointGrid& data, const BoundaryLinkOptions& options,
                                         std::vector<LabelledPoint>* points, int* count = nullptr);

}  // namespace surfmap
