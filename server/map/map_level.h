// Which Loop level to evaluate a map on: fine enough that boundaries are
// resolved below a drag's precision, independent of the levels sampled.
#pragma once

#include "server/mesh/control_mesh.h"
#include "server/mesh/loop_surface.h"

namespace surfmap {

// 1 mm: the level a job's map is served on (GetMap, QueryMap, exports). A
// boundary inside a triangle is placed by linear interpolation over at most
// this much, and a change in a drag is located to ~0.1-0.3 mm. Measured on
// the same drags (54 service maps, 9 scenes x 6 seeds, each re-scored at
// ~2 mm and ~1 mm edges): classified right up on all nine scenes, mu RMSE
// down on all nine (bottle 0.0337 -> 0.0319), boundary error 0.1 mm less
// (docs/method.md section 5), for ~2x the time to build and query the map.
inline constexpr double kMapEdgeMm = 1.0;
// The plan's own map, rebuilt after every drag, is this many levels coarser
// than the served map (~4 mm edges): enough to decide where to drag, at a
// sixteenth of the served map's size.
inline constexpr int kPlanLevelsBelowMap = 2;
// Level 5 of a 1,000-face control mesh is ~1M triangles: the map's graph
// searches stay well under a second.
inline constexpr int kMaxMapLevel = 5;

// The coarsest level whose median edge, halving the control mesh's median
// edge once per level, is at most `edge_mm`, capped at `max_level`; 0 for an
// empty mesh.
int MapLevelFor(const ControlMesh& mesh, double edge_mm = kMapEdgeMm, int max_level = kMaxMapLevel);

// The same from a surface's level 0: its limit positions lie within a
// fraction of an edge of the control mesh's, and on the scan where the
// control mesh is a simplification (the service's jobs and surfmap-mapsim
// both choose the map level this way).
int MapLevelFor(const SurfaceLevel& level0, double edge_mm = kMapEdgeMm, int max_level = kMaxMapLevel);

}  // namespace surfmap
