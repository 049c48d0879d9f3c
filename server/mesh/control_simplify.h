// A coarse control mesh for sampling, made from a dense mesh (a scan) at a
// target site spacing: sites are the control mesh's vertices (and their
// subdivision children), so a 3,000-vertex scan must not give 3,000 level-0
// sites. Simplification is meshoptimizer's meshopt_simplify (quadric edge
// collapse, Debian's libmeshoptimizer-dev 0.18).
#pragma once

#include "absl/status/statusor.h"
#include "server/mesh/control_mesh.h"

namespace surfmap {

struct ControlMeshChoice {
  ControlMesh mesh;
  bool simplified = false;  // false: the mesh was coarse enough and is used as is
  int target_vertices = 0;  // area / spacing^2 (at least kMinControlVertices)
};

// Fewer control vertices than this cannot carry a closed Loop surface well
// (a tetrahedron has 4; an octahedron, 6, is the coarsest that rounds nicely).
inline constexpr int kMinControlVertices = 6;

// The control mesh for sites about `spacing_mm` apart: `dense` itself if it
// has at most (area / spacing^2) x 3 vertices (the hand-made control meshes
// of the scenes are used as they are), else `dense` simplified to about
// area / spacing^2 vertices (then a regular triangulation's mean edge is
// ~1.07 x spacing). The result passes ValidateControlMesh; when a
// simplification fails it (a collapse can pinch an edge into a non-manifold
// one), less aggressive targets are tried; when none is valid (a flat-faced
// CAD part: zero-area triangles along its straight edges), the mesh is
// coarsened exactly (flat_coarsen.h) and refined flat to sqrt(2) x the
// spacing (flat_refine.h), simplified again if still too fine; then
// FAILED_PRECONDITION naming the spacing. INVALID_ARGUMENT for a
// non-positive spacing or an invalid mesh.
absl::StatusOr<ControlMeshChoice> ControlMeshForSpacing(const ControlMesh& dense, double spacing_mm);

}  // namespace surfmap
