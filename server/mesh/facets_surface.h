// The Loop surface of an object whose flat facets are its surface (a CAD
// export: ObjectRecord::surface "facets"). Taken as a control mesh, a box of
// 12 triangles would be a blob up to ~2 cm inside the box.
//
// Sites come from a control mesh refined flat from the facets to edges of
// sqrt(2) x the site spacing (flat_refine.h) or shorter (about area /
// spacing^2 vertices on a box, as control_simplify.h aims for), or, where the facets are already finer, the
// facets simplified as a scan is. Every limit position and normal is then
// projected onto the facets refined to ~2 mm edges (dense_surface.h), with
// normals smoothed across gentle bends only: a face's normal is the face's
// own up to its sharp edges (kCadCreaseAngleDeg), so a site beside an edge
// is commanded with the normal of the face it is on.
#pragma once

#include <memory>

#include "absl/status/statusor.h"
#include "server/mesh/control_mesh.h"
#include "server/mesh/loop_surface.h"

namespace surfmap {

// The refined facets that positions are projected onto have at most this
// many vertices (edges grow past 2 mm on objects above ~0.4 m^2).
inline constexpr int kMaxFacetsProjectionVertices = 200000;

// `facets` must be valid (ValidateControlMesh). `site_spacing_mm` 0: the
// facets themselves are the control mesh, Loop-smoothed and projected back
// (the simulated rig's scene, which rounds edges as a probe tip does).
// Errors: those of RefineFlat, ControlMeshForSpacing and LoopSurface::Create.
absl::StatusOr<std::unique_ptr<LoopSurface>> FacetsSurface(const ControlMesh& facets, int level,
                                                           double site_spacing_mm);

// The object's own shape as the service serves it (GetMesh): the facets
// refined with every edge sharp (LoopSurface::Edges::kSharp), so level 0 is
// the uploaded mesh itself, corners and edges where they are, and every level
// lies on the facets; normals are the facets' refined to ~2 mm, creased as
// above. Taken as a smooth control mesh instead, a 12-triangle box's level-0
// corners were served 28 mm inside the box. Errors: those of RefineFlat and
// LoopSurface::Create.
absl::StatusOr<std::unique_ptr<LoopSurface>> ExactFacetsSurface(const ControlMesh& facets, int level);

}  // namespace surfmap
