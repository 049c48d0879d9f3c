// Following a boundary from the places drags crossed it (PlanMode::kBoundary).
//
// The map joins two crossings of the same boundary only when they are at most
// a link length apart (boundary_links.h, 20 mm); between crossings farther
// apart, data of one region on both sides of a narrow feature pinch it off
// and the map is confident there, so no uncertainty term sends a drag back
// (measured on the banded vase: ~65 mm of band lost between two crossings).
// So the planner follows every boundary it has found: a crossing P, made by a
// drag along d with surface normal n, says the boundary runs along
// t = n x d near P. Where P has no crossing of the same boundary within the
// link length on a side (+t or -t), the next drag goes to
//
//   T = P +/- step t,   step = 0.6 x link length (12 mm)
//
// across the boundary (along d), so that if the boundary goes on roughly
// straight its next crossing lands within linking distance of P, and if it
// turns (a patch's corner), that drag shows where it went or that it ended.
// A side is followed once: a target counts as explored when a drag's data
// window (measured, issued or queued) passes within `explored_mm` of it
// running within 60 degrees of the crossing direction. Each target gets at
// most one drag, so following stops at the boundary's end, where it meets
// crossings already made, or at the budget.
//
// "The same boundary": the same two regions, with region A on the same side
// (a narrow band's two edges are the same pair the other way round), from
// another drag.
//
// SamplingPlanOptions::follow_boundaries turns it on; it is off by default:
// at the default budget it keeps a narrow band whole but takes the follow-up
// drags that found drag-sized patches (docs/method.md section 5, measured
// over six seeds with `surfmap-mapsim --follow-boundaries`).
#pragma once

#include <vector>

#include <Eigen/Core>
#include "server/map/boundary_links.h"
#include "server/map/region_map.h"

namespace surfmap {

struct BoundaryTraceOptions {
  double link_mm = 20.0;           // BoundaryLinkOptions::max_length_mm
  double step_share = 0.6;         // of link_mm
  // A drag's data window passing this close to a target explored it: the
  // crossing would be inside the window, clear of the change detector's
  // guard at the window's ends.
  double explored_mm = 1.5;
  double min_crossing_cos = 0.5;   // a drag within 60 degrees of the crossing direction explores
};

// A stretch of a drag's data window on the surface (a segment of its path).
struct DragSegment {
  Eigen::Vector3d a = Eigen::Vector3d::Zero();
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
};

struct TraceTarget {
  Eigen::Vector3d point = Eigen::Vector3d::Zero();      // where the boundary is expected (off the surface by its curvature)
  Eigen::Vector3d direction = Eigen::Vector3d::Zero();  // unit: across the boundary (the crossing drag's direction)
  int mark = -1;                                        // index of the crossing it continues
  int side = 0;                                         // +1 or -1 along n x d
};

// Targets of every side of every crossing with no partner on that side, in
// mark order (+t before -t), that no drag in `drags` has explored.
std::vector<TraceTarget> OpenTraceTargets(const std::vector<ChangeMark>& marks, const std::vector<DragSegment>& drags,
                                          const BoundaryTraceOptions& options = {});

// The squared error mass (mu^2 mm^2) the map holds along a drag across
// `target` if the boundary of `mark` (the crossing the target continues)
// goes on straight to it: over the drag's data window, target -/+
// half_window_mm along target.direction, the length where the map's region
// is not the one that continuation puts there (the crossing's `before`
// region short of the target, `after` beyond it), times the corridor the
// drag settles (2 x corridor_mm wide) and the squared jump between the two
// regions' mu. Zero where the map already carries the boundary on (linked
// crossings, other drags' data), large where data of one region on both
// sides pinched a narrow feature off. Points are sampled every mm.
double ContinuationError(const TraceTarget& target, const ChangeMark& mark, const RegionMap& map,
                         double half_window_mm, double corridor_mm);

// Whether some drag's segment passes within explored_mm of the target's point,
// running within acos(min_crossing_cos) of its direction.
bool Explored(const TraceTarget& target, const std::vector<DragSegment>& drags, const BoundaryTraceOptions& options);

}  // namespace surfmap
