// The transforms between an object's frame and a rig's base frame, for a
// registration (rig_registration.h): points, directions, forces, whole drag
// traces, and a probe command in the rig's frame with its tool-centre path.
#pragma once

#include <string_view>
#include <vector>

#include <Eigen/Core>

#include "absl/status/statusor.h"
#include "server/estimate/drag_trace.h"
#include "server/frames/rig_registration.h"

namespace surfmap {

// The frame a trace is sent in. Positions are always the contact point.
enum class TraceFrame {
  kObject,               // positions and forces in the object's frame (the mesh's)
  kRigBase,              // positions and forces in the rig's base frame
  kRigBaseSensorForces,  // positions in the base frame, forces in the F/T sensor's frame
};
std::string_view TraceFrameName(TraceFrame frame);  // "object", "rig_base", "rig_base_sensor_forces"
absl::StatusOr<TraceFrame> ParseTraceFrame(std::string_view name);

// p_base = R p_object + t, and back.
Eigen::Vector3d ObjectPointToBase(const RigRegistration& r, const Eigen::Vector3d& p);
Eigen::Vector3d BasePointToObject(const RigRegistration& r, const Eigen::Vector3d& p);
// Directions and forces (no translation).
Eigen::Vector3d ObjectVectorToBase(const RigRegistration& r, const Eigen::Vector3d& v);
Eigen::Vector3d BaseVectorToObject(const RigRegistration& r, const Eigen::Vector3d& v);

// A trace sent in `frame` as the object's frame (what the checks and the fit
// read), and the other way (what a rig recording in its own frame sends).
// kObject is the identity. Times and phases are unchanged.
DragTrace TraceToObjectFrame(const DragTrace& trace, TraceFrame frame, const RigRegistration& r);
DragTrace TraceFromObjectFrame(const DragTrace& trace, TraceFrame frame, const RigRegistration& r);
// A trace whose positions and forces were transformed with the INVERSE of
// the registration (base -> object applied where object -> base was meant),
// read back into the object's frame: a mistake worth naming.
DragTrace InverseRegisteredTraceToObjectFrame(const DragTrace& trace, const RigRegistration& r);

// The commanded drag in the rig's base frame. Contact points throughout; the
// tool centre is the contact point moved tip_radius_mm along the outward
// surface normal, at every point of the drag's path.
struct RigFrameCommand {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();        // the site (contact point)
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();         // outward unit normal at the site
  Eigen::Vector3d drag_direction = Eigen::Vector3d::UnitX(); // unit, forward pass
  Eigen::Vector3d start = Eigen::Vector3d::Zero();           // contact point where the forward pass starts
  Eigen::Vector3d end = Eigen::Vector3d::Zero();             // ... and ends
  std::vector<Eigen::Vector3d> tool_centre_path;             // forward pass, start to end
};

// `path_points` / `path_normals`: the forward pass's contact path on the
// surface in the object's frame (start to end, outward unit normals), e.g.
// LoopSurface::TraceDragPath. An empty path gives start = end = the site.
RigFrameCommand CommandInRigFrame(const RigRegistration& r, const Eigen::Vector3d& position,
                                  const Eigen::Vector3d& normal, const Eigen::Vector3d& drag_direction,
                                  const std::vector<Eigen::Vector3d>& path_points,
                                  const std::vector<Eigen::Vector3d>& path_normals);

// How a trace in the object's frame sits against its command, for telling a
// trace in the wrong frame: the farthest sample from the commanded site, and
// the angle between the mean force over the forward and reverse passes
// (friction cancels between them, the normal force remains) and the
// commanded normal.
struct FrameFit {
  double max_offset_mm = 0.0;
  double force_angle_deg = 180.0;
};
FrameFit MeasureFrameFit(const DragTrace& object_frame_trace, const Eigen::Vector3d& site,
                         const Eigen::Vector3d& normal);

}  // namespace surfmap
