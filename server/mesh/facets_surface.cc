#include "server/mesh/facets_surface.h"

#include <cmath>
#include <utility>

#include "server/base/status_macros.h"
#include "server/mesh/control_simplify.h"
#include "server/mesh/dense_surface.h"
#include "server/mesh/flat_refine.h"
#include "server/mesh/mesh_units.h"

namespace surfmap {

absl::StatusOr<std::unique_ptr<LoopSurface>> FacetsSurface(const ControlMesh& facets, int level,
                                                           double site_spacing_mm) {
  const double area = SurfaceArea(facets);
  SURFMAP_ASSIGN_OR_RETURN(
      ControlMesh fine,
      RefineFlat(facets, FacetedRefineEdgeMm(area, kMaxFacetsProjectionVertices), 2 * kMaxFacetsProjectionVertices));
  ControlMesh control = facets;
  if (site_spacing_mm > 0) {
    SURFMAP_ASSIGN_OR_RETURN(control, RefineFlat(facets, std::sqrt(2.0) * site_spacing_mm,
                                                 4 * kMaxFacetsProjectionVertices));
    // Facets already finer than the spacing are simplified as a scan is (a
    // mesh coarse enough comes back as it is).
    SURFMAP_ASSIGN_OR_RETURN(ControlMeshChoice choice, ControlMeshForSpacing(control, site_spacing_mm));
    control = std::move(choice.mesh);
  }
  const DenseSurface dense(fine, kCadCreaseAngleDeg);
  return LoopSurface::Create(control, level, dense.Projection());
}

}  // namespace surfmap
