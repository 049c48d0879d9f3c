// A faceted mesh (a CAD export: a box as 12 triangles, a cylinder as long
// thin strips) made dense without changing its shape: every edge longer than
// a length is split at its midpoint, which lies on the facets, so the refined
// mesh is the same piecewise-flat surface.
//
// Why: a coarse mesh is used as a Loop control mesh, whose smooth limit
// surface rounds a box's edges and corners by centimetres; a dense mesh is
// the geometry itself (sites come from a simplified control mesh projected
// onto it, control_simplify.h, dense_surface.h). Refining a faceted mesh
// this way puts it on the dense path, so the rig is sent onto the facets.
//
// Longest edges first (a conforming bisection: both triangles on an edge are
// split), so a long thin triangle gets short edges with no angle much
// smaller than its own; it stays a sliver (rounding triangles would need
// remeshing, which moves vertices; the projection needs short edges only).
#pragma once

#include "absl/status/statusor.h"
#include "server/mesh/control_mesh.h"

namespace surfmap {

// The edge length facets are refined to for projecting onto them: 2 mm, or
// longer for a large object so that the mesh stays below about
// `max_vertices` (about 4 x area / length^2 vertices).
double FacetedRefineEdgeMm(double area_mm2, int max_vertices);

// `mesh` (valid, ValidateControlMesh) with every edge longer than
// `max_edge_mm` split at its midpoint. Winding, existing vertices (indices
// and positions) and the surface are kept; new vertices come after the old.
// INVALID_ARGUMENT for a non-positive length; RESOURCE_EXHAUSTED, naming
// the counts, when it would need more than `max_vertices` vertices (checked
// as it goes, before the memory is spent).
absl::StatusOr<ControlMesh> RefineFlat(const ControlMesh& mesh, double max_edge_mm, int max_vertices);

}  // namespace surfmap
