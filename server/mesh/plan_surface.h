// The surface the service plans an object on, when it is not the uploaded
// mesh's own Loop surface. Shared by the service's surface cache
// (server/jobs/surface_cache.cc) and surfmap-mapsim, so both plan alike.
#pragma once

#include <memory>

#include "absl/status/statusor.h"
#include "server/mesh/control_mesh.h"
#include "server/mesh/loop_surface.h"

namespace surfmap {

// At `level`: an object uploaded as facets, its FacetsSurface
// (facets_surface.h) at a spacing, its ExactFacetsSurface at spacing 0 (the
// object's shape: GetMesh); a mesh finer than `site_spacing_mm`, a control mesh
// simplified from it (control_simplify.h) whose limit is projected onto the
// mesh. Null when the mesh is coarse enough to be the control mesh as it is
// (always for a control mesh at spacing 0): the caller refines the mesh
// itself. Errors: those of FacetsSurface, ControlMeshForSpacing and
// LoopSurface::Create.
absl::StatusOr<std::unique_ptr<LoopSurface>> DerivedPlanSurface(const ControlMesh& mesh, bool facets, int level,
                                                                double site_spacing_mm);

}  // namespace surfmap
