// Ground truth of a scene on a Loop surface, for evaluating measured maps.
#pragma once

#include <vector>

#include <Eigen/Core>
#include "clients/sim/rig/scene.h"
#include "server/mesh/loop_surface.h"

namespace surfmap {

struct SceneTruth {
  std::vector<int> material_index;  // into Scene::materials, per point / vertex
  std::vector<double> mu;           // that material's mu
};

// The material of each point (mm).
SceneTruth ClassifyPoints(const Scene& scene, const std::vector<Eigen::Vector3d>& points);

// The truth at every vertex of `level` of `surface` (the finest when level is
// -1), classified at the vertex's limit position. By the LoopSurface
// numbering contract the first N entries are also the truth for the N
// vertices of any coarser level. Levels out of range give empty vectors.
SceneTruth SceneTruthAtVertices(const Scene& scene, const LoopSurface& surface, int level = -1);

}  // namespace surfmap
