// RigDriver: where a robot plugs in. A driver executes one probe command
// (docs/method.md section 1: touch down, forward drag, pause, reverse drag)
// and returns the drag trace it recorded. SimulatedRig implements it for a
// scene; a real robot's driver implements the same interface.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "server/estimate/drag_trace.h"
#include "server/frames/rig_frames.h"

namespace surfmap {

// The command in the rig's base frame (frames and calibration; the server
// sends it when the rig is registered to the object): the server's
// RigFrameCommand (contact points, mm; tool_centre_path ~1 mm apart), with
// the registration it was computed with and that registration's tip.
struct RigFrameRequest {
  std::int64_t registration_id = 0;
  RigFrameCommand command;
  double tip_radius_mm = 0.0;
};

struct ProbeRequest {
  // The site, mm. The drag segment is centred on it (the measurement is
  // attributed to the site), unless the surface ends less than half a segment
  // behind it, when the drag starts there.
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();         // outward unit normal (as planned)
  Eigen::Vector3d drag_direction = Eigen::Vector3d::UnitX(); // tangent, forward pass direction
  double segment_length_mm = 20.0;
  double speed_mm_s = 10.0;
  double normal_force_n = 5.0;
  std::int64_t command_id = 0;  // also seeds simulated rigs: a re-executed command gives the same trace
  // Where the command comes from (for logs and external drivers; 0 when unknown).
  std::int64_t job_id = 0;
  int attempt = 0;                        // 1 = first issue of the site's command
  int site_level = 0;
  int site_vertex = 0;
  std::int64_t lease_deadline_unix_ms = 0;  // a trace answered after this may be refused
  std::optional<RigFrameRequest> rig_frame;  // the same command in the rig's base frame, when registered
};

// INVALID_ARGUMENT naming the field: non-finite vectors, a zero normal or
// direction, length outside (0, 500] mm, speed outside (0, 1000] mm/s, force
// outside (0, 100] N.
absl::Status ValidateProbeRequest(const ProbeRequest& request);

class RigDriver {
 public:
  virtual ~RigDriver() = default;

  // Executes the probe. The error code says what the rig loop reports
  // (ReportFailure's FailureKind) and whether it goes on:
  //   FAILED_PRECONDITION, OUT_OF_RANGE  the rig can never reach or drag at
  //                                      the site: UNREACHABLE (given up)
  //   UNAVAILABLE, DEADLINE_EXCEEDED,    a fault worth retrying (force limit
  //   INVALID_ARGUMENT, others           tripped, lost contact): TRANSIENT
  //   INTERNAL                           the driver itself is broken: TRANSIENT,
  //                                      then the loop stops with the error
  //   ABORTED                            stopped by its operator (e-stop):
  //                                      TRANSIENT, then the loop stops
  virtual absl::StatusOr<DragTrace> Execute(const ProbeRequest& request) = 0;
};

}  // namespace surfmap
