#include "clients/sim/rig/scene_truth.h"

namespace surfmap {

SceneTruth ClassifyPoints(const Scene& scene, const std::vector<Eigen::Vector3d>& points) {
  SceneTruth truth;
  truth.material_index.reserve(points.size());
  truth.mu.reserve(points.size());
  for (const auto& p : points) {
    const int m = scene.MaterialIndexAt(p);
    truth.material_index.push_back(m);
    truth.mu.push_back(scene.materials[m].mu);
  }
  return truth;
}

SceneTruth SceneTruthAtVertices(const Scene& scene, const LoopSurface& surface, int level) {
  if (level == -1) level = surface.max_level();
  if (level < 0 || level > surface.max_level()) return {};
  return ClassifyPoints(scene, surface.level(level).limit_positions);
}

}  // namespace surfmap
