// Chains of links carried on through crossings that drags made obliquely.
//
// A link needs both drags within ~30 degrees of perpendicular to it
// (boundary_links.h): a chord between the two sides of a patch's corner
// looks, from the two crossings alone, like a side crossed obliquely, and
// would cut the corner off. A chain's end knows more: the boundary's
// direction there, along its last link. On the bottle's patches half the
// crossings lie on a side whose other crossings were joined while they
// themselves were left out, their drags running 35-60 degrees off
// perpendicular, and the map bulged between them.
//
// A crossing Q not yet in any chain is joined to a chain end E of the same
// two regions when
//  - the chord E -> Q, in E's tangent plane, turns from the chain's
//    direction by at most max_extension_turn_deg (a corner turns by
//    min_corner_turn_deg or more: it is left to boundary_corners.h);
//  - Q's drag crossed the chord within acos(min_extension_crossing_cos) of
//    perpendicular (it crossed the boundary, not grazed along it), with A
//    on the same side as at E;
//  - it is at most max_extension_length_mm long, the two normals within
//    max_corner_normal_deg, and no data contradicts it (as a link).
// Ends take their nearest such crossing first; Q is then the chain's end,
// and the chain may be carried on again from it.
#pragma once

#include <vector>

#include "server/map/boundary_chains.h"
#include "server/map/boundary_corridor.h"

namespace surfmap {

// `links` with the extensions appended (DrawnLink from = the chain end's mark,
// to = the crossing joined).
std::vector<DrawnLink> ExtendChains(const std::vector<ChangeMark>& marks, std::vector<DrawnLink> links,
                                    const LabelledPointGrid& data, const BoundaryLinkOptions& options);

}  // namespace surfmap
