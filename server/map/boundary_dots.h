// Round regions smaller than a drag, drawn through their crossings.
//
// A dot smaller than a drag is crossed by a few drags. Links join at most
// two neighbouring crossings with a straight chord (boundary_links.h: the
// boundary turns too fast between the others), and elsewhere between
// crossings the random walker draws its edge inside the truth.
// Measured: on the held-out stone (scan_stone_m, seed 6) the map's 16 mm
// sandpaper dot covered 253 of the 323 map vertices inside the true one and
// 2 outside it, short in every direction; over its six seeds 48 of the
// scorer's 5,000 points were the dot's mapped as wood, 4 the other way.
//
// Crossings of one boundary that lie on a circle round the side they enter
// are a dot's edge. The marks of regions {inner, outer}, grouped
// where they lie within 2 max_dot_radius_mm of each other (single linkage),
// make a dot when, in the tangent plane of their centroid (mean normal):
//  - there are at least three of them, their normals within
//    max_corner_normal_deg of the mean;
//  - the least-squares circle through them has a radius from corridor_mm
//    (less is the crossings' own location error) to max_dot_radius_mm, and
//    every mark lies within max_dot_residual_mm of it; of a group of at
//    least min_dot_crossings_to_excuse_one, the one farthest off may lie up
//    to max_dot_outlier_mm off the circle fitted through the others;
//  - every drag entered the inner region running within
//    acos(min_extension_crossing_cos) of the circle's centre (it crossed
//    the edge, not grazed it); with dot_grazing_crossings_on_circle, at
//    least three did, and a grazing one counts as it lies on the circle;
//  - the marks surround the centre (the widest gap between them is under
//    180 degrees), or they span at least min_dot_arc_deg of the circle and
//    other regions' data in the ring just outside it (out to dot_ring_radii
//    radii) close the gap: with the data's angles the widest gap is under
//    180 degrees. Two crossings of each side near a patch's corner lie on
//    a circle too, about the patch's inside; beyond their gap lies the
//    patch, never another region;
//  - no other region's data lie inside it, and no data of the inner region
//    in the ring (the region is larger, or not round);
//  - data near the circle, checked as for a link (boundary_corridor.h) but
//    with max_dot_data_offset_mm for the wrong side's tolerance, contradict
//    at most max_dot_contradicted_chord_share of its chords; those are left
//    out, and the random walker draws the edge there.
// The circle is then drawn as chords of at most max_dot_chord_mm, each with
// the link's seeds either side, and it replaces the links drawn between the
// dot's crossings (boundary_links.cc): two crossings 50 degrees apart round
// a dot are near perpendicular to their chord and get linked, and the chord
// cuts the dot.
#pragma once

#include <vector>

#include "server/map/boundary_chains.h"
#include "server/map/boundary_corridor.h"
#include "server/map/boundary_outlines.h"

namespace surfmap {

using BoundaryDot = BoundaryOutline;

// The dots among the crossings (all of them, linked or not).
std::vector<BoundaryDot> FindDots(const std::vector<ChangeMark>& marks, const LabelledPointGrid& data,
                                  const BoundaryLinkOptions& options);

}  // namespace surfmap
