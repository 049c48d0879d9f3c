// Chooses the data window of a drag: the stretch of path, well inside both
// motions, whose samples the friction and roughness fits use.
#pragma once

#include <span>
#include <string>

#include "absl/status/statusor.h"
#include "server/estimate/drag_trace.h"
#include "server/estimate/path_pairing.h"

namespace surfmap {

struct WindowOptions {
  // Keep only where BOTH passes move at >= this share of their median speed
  // (speed = ds/dt smoothed over +-smoothing_s). This cuts the acceleration and
  // deceleration ramps, where stick-slip shows and where the force controller
  // is still settling after contact or the reversal; the median is the cruise
  // speed whenever the ramps take less than half of a pass.
  double min_speed_fraction = 0.7;
  double smoothing_s = 0.05;
  // ... and trim this share of the common forward/reverse range off each end,
  // a margin that does not depend on the speed estimate (e.g. a pass that
  // never slows down, or ramps shorter than the smoothing).
  double trim_fraction = 0.1;
  bool IsValid(std::string* why) const;
};

struct DataWindow {
  double start_mm = 0.0;  // along the forward path from its first sample
  double end_mm = 0.0;
};

// INVALID_ARGUMENT when the speed and trim rules leave an empty window.
absl::StatusOr<DataWindow> ChooseDataWindow(std::span<const DragSample> forward,
                                            std::span<const DragSample> reverse,
                                            const PathPairing& pairing,
                                            const WindowOptions& options = {});

}  // namespace surfmap
