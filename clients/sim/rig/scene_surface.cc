#include "clients/sim/rig/scene_surface.h"

#include "absl/strings/str_cat.h"
#include "server/mesh/facets_surface.h"
#include "server/mesh/flat_refine.h"

namespace surfmap {
namespace {

// A facets scene's facets are refined flat to edges of at most this before
// Loop refinement: the Loop levels of a coarse CAD mesh (a box's 12
// triangles) are a blob that projection squashes onto the faces unevenly, in
// triangles that fold near the corners; of a mesh this fine they stay within
// ~1 mm of the facets and project onto them in even triangles. A third of a
// 20 mm drag, so a drag crosses a level-0 triangle in a few steps.
constexpr double kFacetsControlEdgeMm = 6.0;
constexpr int kMaxFacetsControlVertices = 4 * kMaxFacetsProjectionVertices;

absl::StatusOr<std::unique_ptr<LoopSurface>> FacetsSceneSurface(const ControlMesh& facets, int level) {
  absl::StatusOr<ControlMesh> control = RefineFlat(facets, kFacetsControlEdgeMm, kMaxFacetsControlVertices);
  if (!control.ok()) return control.status();
  return FacetsSurface(*control, LevelWithinTriangleLimit(*control, level), /*site_spacing_mm=*/0);
}

}  // namespace

absl::StatusOr<std::unique_ptr<LoopSurface>> SceneSurface(const Scene& scene, int level) {
  absl::StatusOr<std::unique_ptr<LoopSurface>> surface =
      scene.facets ? FacetsSceneSurface(scene.mesh, level)
                   : LoopSurface::Create(scene.mesh, LevelWithinTriangleLimit(scene.mesh, level));
  if (!surface.ok()) {
    return absl::InvalidArgumentError(absl::StrCat("scene '", scene.name, "' (", scene.source, "): cannot build its ",
                                                   scene.facets ? "facets" : "Loop", " surface: ",
                                                   surface.status().message()));
  }
  return surface;
}

}  // namespace surfmap
