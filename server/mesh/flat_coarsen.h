// A finely tessellated faceted mesh (a CAD export: a box as 40 x 40 squares
// per face) made as coarse as it can be without changing its shape.
//
// Why: a dense mesh is simplified to a control mesh with meshoptimizer
// (control_simplify.h), whose quadric error is zero for a collapse that moves
// a vertex within a flat face, so it freely moves a face's vertex onto a
// straight sharp edge and leaves triangles whose three corners lie on that
// edge's line: zero area, an invalid control mesh. Measured: a 100 mm box
// tessellated 40 x 40 per face failed at every target. Here only collapses
// that keep the surface exactly are taken:
//   - a vertex inside a flat region (all its triangles in one plane) moves
//     onto a neighbour;
//   - a vertex in the middle of a straight sharp edge or border (exactly two
//     such edges at it, on one line, the triangles on each side flat) moves
//     along that line onto one of its two neighbours on it;
// and only when the triangles it leaves keep their orientation and a shape
// no thinner than a floor. Corners, curved edges and curved regions are
// never moved. The result (a box comes back as about its 8 corners) is then
// refined flat to the site spacing (flat_refine.h).
#pragma once

#include "server/mesh/control_mesh.h"

namespace surfmap {

// Two triangles are taken as coplanar, and three vertices as collinear,
// within this angle (radians). A CAD export in float STL, in metres, has
// normals accurate to a few 1e-6 rad on 1 mm facets; a curved surface
// tessellated for display turns by 1e-2 rad or more per facet.
inline constexpr double kFlatAngleTolerance = 1e-4;

// A triangle a collapse leaves must have area / (longest edge)^2 at least
// this (an equilateral triangle has 0.43; 0.02 is a sliver about 1:25).
inline constexpr double kMinCollapsedShape = 0.02;

// `mesh` (valid, ValidateControlMesh) with every collapse above taken that
// keeps it valid, repeated until none is left. The surface, the winding and
// the open borders are kept; surviving vertices keep their positions and
// their order. Deterministic.
ControlMesh CoarsenFlat(const ControlMesh& mesh);

}  // namespace surfmap
