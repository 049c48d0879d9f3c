#include "clients/haptics/scene/scene_texture_map.h"

#include "clients/sim/rig/scene_truth.h"
#include "server/estimate/roughness.h"

namespace surfmap::haptics {

TextureMap SceneTruthTextureMap(const Scene& scene, const LoopSurface& surface, int level) {
  level = std::clamp(level, 0, surface.max_level());
  const SurfaceLevel& l = surface.level(level);
  const SceneTruth truth = SceneTruthAtVertices(scene, surface, level);
  TextureMap map;
  map.level = level;
  map.grid_step_mm = 0.1;  // DragSimOptions::roughness_step_mm: the scenes' AR models are on this grid
  map.positions = l.limit_positions;
  map.normals = l.limit_normals;
  map.triangles = l.triangles;
  const size_t n = map.positions.size();
  map.mu_std.assign(n, 0.0);
  map.boundary_probability.assign(n, 0.0);
  for (size_t v = 0; v < n; ++v) {
    const Material& m = scene.materials[truth.material_index[v]];
    map.mu.push_back(m.mu);
    map.sigma.push_back(m.sigma);
    map.a1.push_back(m.a1);
    map.a2.push_back(m.a2);
    map.region.push_back(truth.material_index[v]);
  }
  FillReflectionFromAr(map);
  for (size_t i = 0; i < scene.materials.size(); ++i) {
    const Material& m = scene.materials[i];
    TextureRegion r;
    r.region = static_cast<int>(i);
    r.mu = m.mu;
    r.ar_coefficients = {m.a1, m.a2};
    r.reflection = ArToReflection(r.ar_coefficients);
    r.sigma = m.sigma;
    map.regions.push_back(std::move(r));
  }
  return map;
}

}  // namespace surfmap::haptics
