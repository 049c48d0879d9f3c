// Which Loop level to evaluate a map on: fine enough that boundaries are
// resolved below a drag's precision, independent of the levels sampled.
#pragma once

#include "server/mesh/control_mesh.h"

namespace surfmap {

// 2 mm: a boundary inside a triangle is placed by linear interpolation of
// distances over at most this much; a change in a drag is located to
// ~0.1-0.3 mm and boundaries between drags to about half their spacing, so a
// finer level would not change the map, only its cost.
inline constexpr double kMapEdgeMm = 2.0;
// Level 5 of a 1,000-face control mesh is ~1M triangles: the map's graph
// searches stay well under a second.
inline constexpr int kMaxMapLevel = 5;

// The coarsest level whose median edge, halving the control mesh's median
// edge once per level, is at most `edge_mm`, capped at `max_level`; 0 for an
// empty mesh.
int MapLevelFor(const ControlMesh& mesh, double edge_mm = kMapEdgeMm, int max_level = kMaxMapLevel);

}  // namespace surfmap
