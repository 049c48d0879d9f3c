// Lines of crossings that drags made obliquely.
//
// A link needs both of its drags within ~32 degrees of perpendicular to it
// (boundary_links.h), so that a chord between two sides of a patch's corner
// is not drawn. A long straight boundary crossed only by drags the planner
// aimed at other things misses out: on the held-out stone (scan_stone_m,
// seed 4) seven of the eight crossings of one edge of its 7 mm masonite
// strip ran 36-70 degrees off perpendicular, 9-15 mm apart, and none was
// linked; between them the map pinched the strip off as wood (its worst
// region, 67 %).
//
// Three crossings in a row say what two cannot: that the boundary runs
// straight through them. Where it turns (a corner, a dot), the middle one
// lies off the line through the other two. So marks P, Q, R of the same two
// regions, from three different drags, with Q between P and R, are a line when
//  - |PQ| and |QR| are each at least min_corner_link_mm and at most
//    max_length_mm; or, a chord being shorter (down to min_line_chord_mm),
//    |PR| is at least min_corner_link_mm: the crossings' ~0.3 mm location
//    error turns a chord shorter than that by more than ~4 degrees, and the
//    line's direction is what its chains carry on (crossings a few mm apart
//    on a drag-sized patch's side, held_vase seed 10);
//  - the chord turns at Q by at most max_line_turn_deg, in Q's tangent plane
//    (a corner turns by min_corner_turn_deg or more);
//  - the normals of P and R are within max_corner_normal_deg of Q's;
//  - region A lies on the same side at all three, each drag crossing its
//    chords within max_line_crossing_deg of perpendicular (it crossed the
//    boundary, not grazed along it);
//  - no data contradicts either chord (boundary_corridor.h).
// PQ and QR are then drawn as links, and the chains they make are carried on
// as any other (boundary_extensions.h). Lines of less turn go first; a mark
// keeps at most one link on each side, so lines never make a web. A side
// held by a hanging link (its far mark has no other link, and it runs
// min_hanging_link_angle_deg or more off the line) is taken from it
// (BoundaryLinkOptions::min_hanging_link_angle_deg): two crossings that
// left a strip obliquely through its two edges are consistent with a chord
// across it, and only the edge's line says the strip runs on.
#pragma once

#include <vector>

#include "server/map/boundary_chains.h"
#include "server/map/boundary_corridor.h"

namespace surfmap {

// `links` with the lines' links appended (each: from = the outer mark, to =
// the middle one).
std::vector<DrawnLink> DrawLines(const std::vector<ChangeMark>& marks, std::vector<DrawnLink> links,
                                 const LabelledPointGrid& data, const BoundaryLinkOptions& options);

}  // namespace surfmap
