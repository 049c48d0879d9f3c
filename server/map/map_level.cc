#include "server/map/map_level.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace surfmap {

int MapLevelFor(const ControlMesh& mesh, double edge_mm, int max_level) {
  std::vector<double> lengths;
  for (const auto& t : mesh.triangles) {
    for (int i = 0; i < 3; ++i) {
      const int a = t[i], b = t[(i + 1) % 3];
      if (a < 0 || b < 0 || a >= static_cast<int>(mesh.positions.size()) || b >= static_cast<int>(mesh.positions.size())) {
        continue;
      }
      lengths.push_back((mesh.positions[a] - mesh.positions[b]).norm());
    }
  }
  if (lengths.empty() || !(edge_mm > 0.0)) return 0;
  std::nth_element(lengths.begin(), lengths.begin() + lengths.size() / 2, lengths.end());
  double edge = lengths[lengths.size() / 2];
  int level = 0;
  while (edge > edge_mm && level < max_level) {
    edge *= 0.5;
    ++level;
  }
  return level;
}

int MapLevelFor(const SurfaceLevel& level0, double edge_mm, int max_level) {
  ControlMesh mesh;
  mesh.positions = level0.limit_positions;
  mesh.triangles = level0.triangles;
  return MapLevelFor(mesh, edge_mm, max_level);
}

}  // namespace surfmap
