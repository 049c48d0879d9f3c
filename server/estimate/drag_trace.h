// A drag trace: one probe measurement (forward pass, pause, reverse pass).
//
// Units: t in s, positions in mm, forces in N. The force is the force exerted
// BY the surface ON the probe: its normal part points out of the surface, its
// friction part points against the motion. Samples are in time order: every
// forward sample, then the pause, then the reverse pass.
#pragma once

#include <string_view>
#include <vector>

#include <Eigen/Core>

namespace surfmap {

enum class DragPhase { kForward, kPause, kReverse };

// "fwd", "pause", "rev" (the CSV spelling).
std::string_view DragPhaseName(DragPhase phase);

struct DragSample {
  double t = 0.0;                               // s
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  // mm
  Eigen::Vector3d force = Eigen::Vector3d::Zero();     // N, by the surface on the probe
  DragPhase phase = DragPhase::kForward;
};

struct DragTrace {
  std::vector<DragSample> samples;
};

}  // namespace surfmap
