#include "server/mesh/facets_surface.h"

#include <cmath>
#include <utility>

#include "server/base/status_macros.h"
#include "server/mesh/control_simplify.h"
#include "server/mesh/dense_surface.h"
#include "server/mesh/flat_refine.h"
#include "server/mesh/mesh_units.h"

namespace surfmap {

namespace {

// The facets refined to ~2 mm that positions and normals are projected onto
// (as a DenseSurface with creased normals, built in place: its search tree
// points into it).
absl::StatusOr<ControlMesh> ProjectionFacets(const ControlMesh& facets) {
  return RefineFlat(facets, FacetedRefineEdgeMm(SurfaceArea(facets), kMaxFacetsProjectionVertices),
                    2 * kMaxFacetsProjectionVertices);
}

}  // namespace

absl::StatusOr<std::unique_ptr<LoopSurface>> ExactFacetsSurface(const ControlMesh& facets, int level) {
  SURFMAP_ASSIGN_OR_RETURN(const ControlMesh fine, ProjectionFacets(facets));
  const DenseSurface dense(fine, kCadCreaseAngleDeg);
  return LoopSurface::Create(facets, level, dense.Projection(), LoopSurface::Edges::kSharp);
}

absl::StatusOr<std::unique_ptr<LoopSurface>> FacetsSurface(const ControlMesh& facets, int level,
                                                           double site_spacing_mm) {
  SURFMAP_ASSIGN_OR_RETURN(const ControlMesh fine, ProjectionFacets(facets));
  const DenseSurface dense(fine, kCadCreaseAngleDeg);
  ControlMesh control = facets;
  if (site_spacing_mm > 0) {
    SURFMAP_ASSIGN_OR_RETURN(control, RefineFlat(facets, std::sqrt(2.0) * site_spacing_mm,
                                                 4 * kMaxFacetsProjectionVertices));
    // Facets already finer than the spacing are simplified as a scan is (a
    // mesh coarse enough comes back as it is).
    SURFMAP_ASSIGN_OR_RETURN(ControlMeshChoice choice, ControlMeshForSpacing(control, site_spacing_mm));
    control = std::move(choice.mesh);
  }
  return LoopSurface::Create(control, level, dense.Projection());
}

}  // namespace surfmap
