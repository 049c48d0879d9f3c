// `surfmap-rig --realtime`: a simulated drag takes as long as the real one
// would. The simulator answers at once; this decorator then sleeps for the
// trace's own duration (its first to last sample: forward pass, pause and
// reverse pass at the commanded speed), so a dashboard or `surfmap watch`
// shows a job progressing at a lab rig's pace. The sleep ends early when the
// stop flag is set (Ctrl-C), and the trace is then returned as measured.
#pragma once

#include <atomic>

#include "clients/sim/rig/rig_driver.h"

namespace surfmap::rig {

class RealtimeDriver : public RigDriver {
 public:
  // `stop` may be null.
  RealtimeDriver(RigDriver& rig, const std::atomic<bool>* stop) : rig_(rig), stop_(stop) {}
  absl::StatusOr<DragTrace> Execute(const ProbeRequest& request) override;

 private:
  RigDriver& rig_;
  const std::atomic<bool>* stop_;
};

// The time a trace covers, s (0 for fewer than two samples).
double TraceDurationSeconds(const DragTrace& trace);

}  // namespace surfmap::rig
