#include "server/frames/rig_frames.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "absl/strings/str_cat.h"

namespace surfmap {
namespace {

constexpr double kPi = 3.14159265358979323846;

template <typename PointMap, typename ForceMap>
DragTrace MapTrace(const DragTrace& trace, PointMap point, ForceMap force) {
  DragTrace out;
  out.samples.reserve(trace.samples.size());
  for (const DragSample& s : trace.samples) {
    DragSample d = s;
    d.position = point(s.position);
    d.force = force(s.force);
    out.samples.push_back(d);
  }
  return out;
}

}  // namespace

std::string_view TraceFrameName(TraceFrame frame) {
  switch (frame) {
    case TraceFrame::kObject: return "object";
    case TraceFrame::kRigBase: return "rig_base";
    case TraceFrame::kRigBaseSensorForces: return "rig_base_sensor_forces";
  }
  return "object";
}

absl::StatusOr<TraceFrame> ParseTraceFrame(std::string_view name) {
  for (TraceFrame f : {TraceFrame::kObject, TraceFrame::kRigBase, TraceFrame::kRigBaseSensorForces}) {
    if (name == TraceFrameName(f)) return f;
  }
  return absl::InvalidArgumentError(
      absl::StrCat("unknown trace frame \"", std::string(name), "\"; expected object, rig_base or rig_base_sensor_forces"));
}

Eigen::Vector3d ObjectPointToBase(const RigRegistration& r, const Eigen::Vector3d& p) {
  return r.object_rotation * p + r.object_translation_mm;
}
Eigen::Vector3d BasePointToObject(const RigRegistration& r, const Eigen::Vector3d& p) {
  return r.object_rotation.conjugate() * (p - r.object_translation_mm);
}
Eigen::Vector3d ObjectVectorToBase(const RigRegistration& r, const Eigen::Vector3d& v) { return r.object_rotation * v; }
Eigen::Vector3d BaseVectorToObject(const RigRegistration& r, const Eigen::Vector3d& v) {
  return r.object_rotation.conjugate() * v;
}

DragTrace TraceToObjectFrame(const DragTrace& trace, TraceFrame frame, const RigRegistration& r) {
  switch (frame) {
    case TraceFrame::kObject: return trace;
    case TraceFrame::kRigBase:
      return MapTrace(trace, [&](const Eigen::Vector3d& p) { return BasePointToObject(r, p); },
                      [&](const Eigen::Vector3d& f) { return BaseVectorToObject(r, f); });
    case TraceFrame::kRigBaseSensorForces:
      return MapTrace(trace, [&](const Eigen::Vector3d& p) { return BasePointToObject(r, p); },
                      [&](const Eigen::Vector3d& f) { return BaseVectorToObject(r, r.sensor_rotation * f); });
  }
  return trace;
}

DragTrace TraceFromObjectFrame(const DragTrace& trace, TraceFrame frame, const RigRegistration& r) {
  switch (frame) {
    case TraceFrame::kObject: return trace;
    case TraceFrame::kRigBase:
      return MapTrace(trace, [&](const Eigen::Vector3d& p) { return ObjectPointToBase(r, p); },
                      [&](const Eigen::Vector3d& f) { return ObjectVectorToBase(r, f); });
    case TraceFrame::kRigBaseSensorForces:
      return MapTrace(trace, [&](const Eigen::Vector3d& p) { return ObjectPointToBase(r, p); },
                      [&](const Eigen::Vector3d& f) {
                        return Eigen::Vector3d(r.sensor_rotation.conjugate() * ObjectVectorToBase(r, f));
                      });
  }
  return trace;
}

DragTrace InverseRegisteredTraceToObjectFrame(const DragTrace& trace, const RigRegistration& r) {
  // The sender applied base -> object to object-frame data: q = R^T (p_obj - t), so p_obj = R q + t.
  return MapTrace(trace, [&](const Eigen::Vector3d& q) { return ObjectPointToBase(r, q); },
                  [&](const Eigen::Vector3d& f) { return ObjectVectorToBase(r, f); });
}

RigFrameCommand CommandInRigFrame(const RigRegistration& r, const Eigen::Vector3d& position,
                                  const Eigen::Vector3d& normal, const Eigen::Vector3d& drag_direction,
                                  const std::vector<Eigen::Vector3d>& path_points,
                                  const std::vector<Eigen::Vector3d>& path_normals) {
  RigFrameCommand c;
  c.position = ObjectPointToBase(r, position);
  c.normal = ObjectVectorToBase(r, normal).normalized();
  c.drag_direction = ObjectVectorToBase(r, drag_direction).normalized();
  if (path_points.empty()) {
    c.start = c.end = c.position;
    c.tool_centre_path.push_back(c.position + r.tip_radius_mm * c.normal);
    return c;
  }
  c.start = ObjectPointToBase(r, path_points.front());
  c.end = ObjectPointToBase(r, path_points.back());
  c.tool_centre_path.reserve(path_points.size());
  for (size_t i = 0; i < path_points.size(); ++i) {
    const Eigen::Vector3d n = i < path_normals.size() ? path_normals[i].normalized() : normal.normalized();
    c.tool_centre_path.push_back(ObjectPointToBase(r, path_points[i] + r.tip_radius_mm * n));
  }
  return c;
}

FrameFit MeasureFrameFit(const DragTrace& trace, const Eigen::Vector3d& site, const Eigen::Vector3d& normal) {
  FrameFit fit;
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (const DragSample& s : trace.samples) {
    fit.max_offset_mm = std::max(fit.max_offset_mm, (s.position - site).norm());
    if (s.phase != DragPhase::kPause) sum += s.force;
  }
  if (sum.norm() > 0 && normal.norm() > 0) {
    const double c = sum.normalized().dot(normal.normalized());
    fit.force_angle_deg = std::acos(std::clamp(c, -1.0, 1.0)) * 180.0 / kPi;
  }
  return fit;
}

}  // namespace surfmap
