// A straight boundary carried on where the region on its far side changes.
//
// Links, lines and extensions join crossings of the same two regions. A
// strip that runs through a patch has edges of one pair outside the patch
// (rubber/wood) and of another inside it (rubber/masonite); drags that
// cross it inside the patch are few, so the chain of each edge stops at the
// patch's side, and the random walker, with the patch's data on both sides
// of the strip and none of the strip itself, pinches the strip off across
// the patch. Measured: on big_block_m (a 7 mm rubber strip through a 40 x
// 30 mm masonite patch) the map drew 50-60 of the strip's 400 scored points
// as masonite on most seeds, the scene's most frequent missed goal.
//
// Two chain ends E1 and E2 (boundary_chains.h) that share a region R are
// bridged when the region beyond the chord changes along it: O1 and O2
// beyond the two ends differ, or (a strip's edge, rubber/wood at both ends
// outside the patch) the data beyond the chord's middle is of a third
// region; where either of the two regions of such ends could be R, the one
// whose far side changes is, and when both could, none is drawn. And
//  - each end's chain points at the other: the chord E1 -> E2 turns from
//    E1's direction, and E2 -> E1 from E2's, by at most max_line_turn_deg
//    (a straight boundary; the same bound as a line of three crossings);
//  - it is longer than min_corner_link_mm and at most max_bridge_mm, the
//    two normals within max_corner_normal_deg;
//  - R lies on the same side of the chord at both ends;
//  - a third region shows beyond the chord for at least max_length_mm (a
//    link's length) wherever it shows: shorter, it is as likely the data
//    beyond a narrow neighbour that no drag measured there (measured: the
//    bridges drawn on 141 stored jobs against a third region for 4-10 mm
//    were all wrong, the 35 mm ones right; docs/method.md);
//  - no data contradicts it: the chord is cut where the nearest data on its
//    far side (within max_length_mm) changes region, and no stretch has
//    data of a third region within corridor_mm of it (as a link) or data on
//    the wrong side by more than bridge_tolerance_mm (out to twice that): a
//    link refuses a quarter of a millimetre, but a bridge's chord is known
//    only from its two ends, and the pieces beside it are where their drags'
//    change tests and the map's split put the changes.
// The bridge is then drawn as those stretches, each with its own far
// region. Nearest pairs first; an end takes part in one bridge.
#pragma once

#include <vector>

#include "server/map/boundary_chains.h"
#include "server/map/boundary_corridor.h"

namespace surfmap {

// The bridges' labelled points; *bridges (if given) receives how many were
// drawn. options.max_bridge_mm = 0: none.
std::vector<LabelledPoint> BoundaryBridgePoints(const std::vector<ChangeMark>& marks,
                                                const std::vector<DrawnLink>& links, const LabelledPointGrid& data,
                                                const BoundaryLinkOptions& options, int* bridges = nullptr);

}  // namespace surfmap
