// The true surface of a scene, which the simulated rig drags and the scorer
// judges maps on: the Loop limit surface of a control-mesh scene, or the flat
// facets of a CAD scene ("surface": "facets", Scene::facets), as the service
// serves such an object (server/mesh/facets_surface.h).
#pragma once

#include <memory>

#include "absl/status/statusor.h"
#include "clients/sim/rig/scene.h"
#include "server/mesh/loop_surface.h"

namespace surfmap {

// The scene's surface refined to `level`, or the finest level within
// kMaxFinestTriangles for a mesh too dense for it (LevelWithinTriangleLimit).
// A facets scene's levels are refined from its facets refined flat to ~6 mm
// edges, and every position is projected onto the facets. Errors: INVALID_ARGUMENT naming the scene
// when its mesh is refused.
absl::StatusOr<std::unique_ptr<LoopSurface>> SceneSurface(const Scene& scene, int level);

}  // namespace surfmap
