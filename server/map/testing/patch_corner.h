// Test support (header-only, not part of the library): drags crossing the
// sides of a square patch near its corner, for the corner and dot tests.
#pragma once

#include <vector>

#include <Eigen/Core>
#include "server/map/boundary_links.h"

namespace surfmap::testing {

// A square patch (region 1) in the quadrant x < 0, y < 0 of the plate z = 0,
// region 0 around it. Its side x = 0 is crossed by drags along +x, its side
// y = 0 by drags along +y; the corner at the origin by none.
inline int PatchTruth(const Eigen::Vector3d& p) { return p.x() < 0.0 && p.y() < 0.0 ? 1 : 0; }

using PatchTruthFn = int (*)(const Eigen::Vector3d&);

inline ChangeMark PatchMark(const Eigen::Vector3d& at, const Eigen::Vector3d& direction, int drag,
                            PatchTruthFn truth = PatchTruth) {
  ChangeMark m;
  m.position = at;
  m.direction = direction;
  m.normal = Eigen::Vector3d::UnitZ();
  m.before = truth(at - 0.5 * direction);
  m.after = truth(at + 0.5 * direction);
  m.drag = drag;
  return m;
}

// Crossings and their drags' data, every 0.5 mm for data_mm either side of
// each crossing, labelled by `truth` (PatchTruth unless set).
struct PatchScene {
  double data_mm = 8.0;
  PatchTruthFn truth = PatchTruth;
  std::vector<ChangeMark> marks;
  std::vector<LabelledPoint> data;
  void Drag(const Eigen::Vector3d& crossing, const Eigen::Vector3d& direction) {
    marks.push_back(PatchMark(crossing, direction, static_cast<int>(marks.size()), truth));
    for (double s = -data_mm; s <= data_mm; s += 0.5) {
      if (s == 0.0) continue;
      const Eigen::Vector3d p = crossing + s * direction;
      data.push_back({p, truth(p)});
    }
  }
};

// Two crossings of each side, `near` mm from the corner and 10 mm farther.
inline PatchScene PatchCorner(double near, double data_mm = 8.0) {
  PatchScene scene;
  scene.data_mm = data_mm;
  scene.Drag({0.0, -near, 0.0}, Eigen::Vector3d::UnitX());
  scene.Drag({0.0, -near - 10.0, 0.0}, Eigen::Vector3d::UnitX());
  scene.Drag({-near, 0.0, 0.0}, Eigen::Vector3d::UnitY());
  scene.Drag({-near - 10.0, 0.0, 0.0}, Eigen::Vector3d::UnitY());
  return scene;
}

}  // namespace surfmap::testing
