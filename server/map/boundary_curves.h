// Links drawn as a smooth curve through a chain's crossings, not a chord.
//
// A link joins two neighbouring crossings of one boundary (boundary_links.h).
// Drawn straight, a chain of links is a polygon inscribed in the boundary:
// where the boundary curves within the surface (a dot, a rounded patch, a
// band that winds) every link cuts the arc it spans, by a sagitta of
// L^2 / (8 r) - 1 mm for a 10 mm link round a dot of radius 12, and the
// region on the inside loses the whole segment. The chain itself says how
// the boundary turns: at a crossing joined on both sides, the boundary's
// direction is, to second order, along the chord from the previous crossing
// to the next (the Catmull-Rom tangent). So a link whose two ends carry such
// a direction, and where the chain turns the same way at both (as along an
// arc), is drawn as the cubic Hermite curve between them. A lone link, a
// chain's last link and a straight chain stay chords, and so do the links
// either side of a crossing located off its boundary: the chain zigzags
// there (one way in, the other way out), and a curve would carry that
// crossing's error on into its neighbours.
//
// The curve replaces the chord only where no data contradicts it (the same
// corridor check, along the curve). An end takes the chain's direction only
// where the chain turns there by at most BoundaryLinkOptions::
// max_curve_turn_deg (more is a corner or a hairpin, which a cubic through
// three points would overshoot).
#pragma once

#include <vector>

#include <Eigen/Core>
#include "server/map/boundary_chains.h"
#include "server/map/boundary_corridor.h"
#include "server/map/boundary_links.h"

namespace surfmap {

// The labelled points of every link in `links`: along its curve where both
// ends take their chain's direction, the chain turns the same way at both
// and `data` does not contradict the curve; along its chord otherwise
// (AppendSegmentSeeds).
// *curved (if given) receives how many links were drawn through their
// chain's tangents (a straight chain's links too) rather than as chords.
std::vector<LabelledPoint> LinkSeeds(const std::vector<ChangeMark>& marks, const std::vector<DrawnLink>& links,
                                     const LabelledPointGrid& data, const BoundaryLinkOptions& options,
                                     int* curved = nullptr);

}  // namespace surfmap
