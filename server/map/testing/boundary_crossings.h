// Test support (header-only, not part of the library): drags crossing a
// straight boundary, for the link, extension and corner tests.
#pragma once

#include <cmath>
#include <numbers>
#include <vector>

#include <Eigen/Core>
#include "server/map/boundary_links.h"

namespace surfmap::testing {

// A straight boundary x = 0 on the plate z = 0: region 0 at x < 0, region 1
// at x > 0. A drag crosses it at (0, y) from region 0 into region 1 along +x
// turned by `off_deg` towards +y (its angle off perpendicular to the
// boundary).
inline ChangeMark Crossing(double y, int drag, double off_deg = 0.0) {
  const double a = off_deg * std::numbers::pi / 180.0;
  ChangeMark m;
  m.position = {0.0, y, 0.0};
  m.direction = {std::cos(a), std::sin(a), 0.0};
  m.normal = Eigen::Vector3d::UnitZ();
  m.before = 0;
  m.after = 1;
  m.drag = drag;
  return m;
}

// Each crossing's drag data: every 1 mm along its direction for 8 mm either
// side, labelled by the side of the boundary x = 0 it lies on.
inline std::vector<LabelledPoint> DragData(const std::vector<ChangeMark>& marks) {
  std::vector<LabelledPoint> data;
  for (const ChangeMark& m : marks) {
    for (double t = -8.0; t <= 8.0; t += 1.0) {
      if (t == 0.0) continue;
      const Eigen::Vector3d p = m.position + t * m.direction;
      data.push_back({p, p.x() < 0.0 ? 0 : 1});
    }
  }
  return data;
}

// How many links BoundaryLinkPoints draws through `marks`, with their drags'
// data (DragData).
inline int LinksDrawn(const std::vector<ChangeMark>& marks, const BoundaryLinkOptions& o = {}) {
  int links = 0;
  BoundaryLinkPoints(marks, DragData(marks), o, &links);
  return links;
}

}  // namespace surfmap::testing
