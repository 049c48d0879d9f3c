// A scene's TRUTH as a TextureMap: the mesh of one level of the scene's Loop
// surface with each vertex's true material (mu, AR(2) roughness) and one
// region per material. A realistic model for the renderer's benchmark and
// tests (the same geometry and textures a perfect map would hold), and the
// reference the realism bench compares against.
#pragma once

#include "server/haptics/texture_map.h"
#include "clients/sim/rig/scene.h"
#include "server/mesh/loop_surface.h"

namespace surfmap::haptics {

// Regions are the scene's materials in Scene::materials order (region i =
// material i, mu_se 0, roughness from the material); mu_std 0 and
// boundary_probability 0 everywhere; grid step 0.1 mm (the simulator's).
// `level` is clamped into the surface's levels.
TextureMap SceneTruthTextureMap(const Scene& scene, const LoopSurface& surface, int level);

}  // namespace surfmap::haptics
