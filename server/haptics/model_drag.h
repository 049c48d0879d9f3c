// A drag over the MODEL: the renderer driven along a path like the rig's
// probe (forward pass, pause, reverse pass over the same path at constant
// speed and normal force), recorded in the drag-trace format of a measured
// trace (server/estimate/drag_trace.h), so a rendered drag can be compared
// with a measured one or fed to the same estimator. Used by the SimulateDrag
// RPC, `surfmap map simulate-drag` and the realism bench.
//
// Force by the surface on the probe: F = Fn n + friction + roughness (the
// renderer's tangential forces), no sensor noise or rig disturbances: the
// model as a haptic display would play it. In the pause the probe is still
// and only the normal force acts.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>
#include "absl/status/statusor.h"
#include "server/haptics/texture_renderer.h"
#include "server/estimate/drag_trace.h"

namespace surfmap::haptics {

struct ModelDragOptions {
  double speed_mm_s = 10.0;
  double sample_rate_hz = 100.0;
  double normal_force_n = 5.0;
  double pause_s = 0.5;
  // False (with a reason) unless speed, rate and force are finite and > 0
  // and the pause finite and >= 0.
  bool IsValid(std::string* why) const;
};

// The rendered drag with what the renderer saw at each sample.
struct ModelDrag {
  DragTrace trace;
  std::vector<double> mu;            // per sample
  std::vector<double> roughness_n;   // r per sample (0 in the pause)
  std::vector<double> arc_length_mm; // the probe's arc length
  std::vector<int> region;
};

// Renders a drag along `path` (points on or near the model surface, mm, in
// drag order; consecutive duplicates are skipped): samples every
// speed / rate mm of polyline length, forward to the end, the pause, then
// back to the start. Errors: INVALID_ARGUMENT for invalid options, fewer than
// two distinct points, non-finite points, or a path with more than 10^7
// samples; FAILED_PRECONDITION when a point is out of the renderer's contact
// distance.
absl::StatusOr<ModelDrag> RenderDragAlongPath(const TextureRenderer& renderer, const std::vector<Eigen::Vector3d>& path,
                                              const ModelDragOptions& options);

// A path of `length_mm` on the model's mesh from `start` (projected) along
// the tangent direction nearest `direction`: steps of `step_mm`, each
// re-projected onto the surface, the direction carried along (its normal
// component removed at every step). Errors: INVALID_ARGUMENT for a
// non-finite or zero direction, one along the normal, a length or step not
// > 0, length / step above `max_steps` (and max_steps outside 1..10^6);
// FAILED_PRECONDITION when `start` is farther than the contact distance from
// the surface, or when the path takes more than `max_steps` steps (steps the
// surface keeps shortening would otherwise never cover the length).
absl::StatusOr<std::vector<Eigen::Vector3d>> TraceModelPath(const TextureRenderer& renderer,
                                                            const Eigen::Vector3d& start,
                                                            const Eigen::Vector3d& direction, double length_mm,
                                                            double step_mm = 0.25, int max_steps = 1000000);

}  // namespace surfmap::haptics
