// Locating an imported drag on the job's object: the probe command the drag
// would have answered had the planner issued it (the "implied command"), so
// an imported trace passes the same plausibility checks as a leased one
// (trace_plausibility.h) instead of a second, drifting copy of them.
//
// From the forward pass's path: the site is the surface point closest to the
// point halfway along it (arc length), the normal the surface's there, the
// drag direction the forward chord projected onto the tangent plane; the
// probe parameters are the job's (a drag much longer, slower or harder than
// the job's fails the same length, time and force checks a rig's would). The
// site's vertex is the finest vertex nearest that point: imports mark no site
// measured (SamplingPlan::RecordImportedLineSample), it only names where the
// drag lies.
//
// A commanded site is on the surface by construction, so the command checks
// alone would pass a path hovering millimetres above it: the largest distance
// of any sample from the surface is measured too (FarthestFromSurface), for
// CheckTraceNearSurface. Locating costs one closest-point query; the distance
// check one per sample, so the importer runs it only after the cheap command
// checks (a malformed file is refused as malformed, not kept as off the
// surface, and a file of 1e6 samples that fails on length costs no queries).
#pragma once

#include "absl/status/statusor.h"
#include "server/estimate/drag_trace.h"
#include "server/mesh/loop_surface.h"
#include "server/plan/probe_command.h"

namespace surfmap {

struct LocatedDrag {
  ProbeCommand command;                    // sequence 0; site = (finest level, nearest vertex)
};

struct SurfaceDistance {
  double max_mm = 0.0;   // of any sample from the finest limit surface
  int sample = 0;        // its index
};

// INVALID_ARGUMENT ("malformed trace: ...") for a trace without forward
// samples or with a non-finite position (the CSV reader refuses both; other
// sources must too). O(samples + log triangles): one closest-point query.
absl::StatusOr<LocatedDrag> LocateImportedDrag(const DragTrace& trace, const LoopSurface& surface,
                                               const ProbeParameters& probe);

// The sample farthest from the surface. O(samples x log triangles).
SurfaceDistance FarthestFromSurface(const DragTrace& trace, const LoopSurface& surface);

}  // namespace surfmap
