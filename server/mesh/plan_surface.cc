#include "server/mesh/plan_surface.h"

#include "server/mesh/control_simplify.h"
#include "server/mesh/dense_surface.h"
#include "server/mesh/facets_surface.h"

namespace surfmap {

absl::StatusOr<std::unique_ptr<LoopSurface>> DerivedPlanSurface(const ControlMesh& mesh, bool facets, int level,
                                                                double site_spacing_mm) {
  if (facets) return site_spacing_mm > 0 ? FacetsSurface(mesh, level, site_spacing_mm) : ExactFacetsSurface(mesh, level);
  if (!(site_spacing_mm > 0)) return nullptr;
  absl::StatusOr<ControlMeshChoice> control = ControlMeshForSpacing(mesh, site_spacing_mm);
  if (!control.ok()) return control.status();
  if (!control->simplified) return nullptr;
  const DenseSurface dense(mesh);
  return LoopSurface::Create(control->mesh, level, dense.Projection());
}

}  // namespace surfmap
