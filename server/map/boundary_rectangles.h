// Small rectangular patches (labels, tape, sandpaper squares), drawn through
// their crossings.
//
// A patch no longer than a drag and a half is crossed by a few drags, each
// side often by one: its sides show no direction, links cut its corners
// (boundary_corners.h needs one straight side to square a corner), and the
// random walker draws its edge midway between the data either side. On
// scan_handle_m (a 24 x 16 mm paper label turned 30 degrees on a handle of
// radius 13-20 mm) seed 1's ten crossings lay on the label's four sides
// within 0.3 mm, yet the map cut a 14 x 6 mm triangle off one corner and a
// 2 mm strip off a side a drag ran along just outside (docs/method.md).
//
// The marks of one region with any others, grouped where they lie within
// max_rectangle_side_mm of each other (single linkage), make a rectangle
// when, in the plane of their mean normal (each normal within
// max_corner_normal_deg of it):
//  - there are at least min_rectangle_crossings of them (a rectangle has
//    five parameters: one crossing more checks it), and none is part of a
//    dot (boundary_dots.h: those are round);
//  - the rectangle whose sides they lie on best (the orientation of least
//    largest residual, each side through the mean of its crossings) has
//    every crossing within max_dot_residual_mm of a side, every side
//    crossed farther than corridor_mm from its corners (a crossing at a
//    corner lies on both sides) or, with rectangle_sides_closed_by_data,
//    other regions' data running along half its length or more just
//    outside it (within corridor_mm), and sides from 2 corridor_mm to
//    max_rectangle_side_mm long;
//  - every drag entered the patch through its side (ran inwards across it);
//  - no data contradicts it: no other region's data inside it nor the
//    region's own outside it beyond corridor_mm (out to corridor_mm +
//    ring; with rectangle_data_on_patch_sheet only data within 2
//    corridor_mm of the band off the plane where its crossings lie: a
//    label on a handle lies over the handle's far side), and near each chord nothing more than max_dot_data_offset_mm
//    on its wrong side; chords so contradicted are left out while at most
//    max_dot_contradicted_chord_share are (as for dots).
// An L, a triangle or a round patch leaves crossings off every rectangle's
// sides. The sides are drawn as chords of at most max_dot_chord_mm in that
// plane; each chord's outer region is that of the nearest data beyond it,
// and its seeds are carried along the plane's normal onto the surface
// (BoundaryOutline::project_along): the patch's edge, seen in the plane,
// is straight there, and on a handle of radius 15 mm the nearest surface
// point to a point of the plane 12 mm out lies 3.8 mm short of it.
#pragma once

#include <set>
#include <vector>

#include "server/map/boundary_corridor.h"
#include "server/map/boundary_outlines.h"

namespace surfmap {

// The rectangles among the crossings, none of whose marks is in `taken`.
std::vector<BoundaryOutline> FindRectangles(const std::vector<ChangeMark>& marks, const LabelledPointGrid& data,
                                            const BoundaryLinkOptions& options, const std::set<int>& taken);

}  // namespace surfmap
