#include "clients/rig/realtime_driver.h"

#include <algorithm>
#include <chrono>
#include <thread>

namespace surfmap::rig {

double TraceDurationSeconds(const DragTrace& trace) {
  if (trace.samples.size() < 2) return 0.0;
  return std::max(0.0, trace.samples.back().t - trace.samples.front().t);
}

absl::StatusOr<DragTrace> RealtimeDriver::Execute(const ProbeRequest& request) {
  const auto start = std::chrono::steady_clock::now();
  absl::StatusOr<DragTrace> trace = rig_.Execute(request);
  if (!trace.ok()) return trace;
  const auto end = start + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                               std::chrono::duration<double>(TraceDurationSeconds(*trace)));
  // In small steps, so a stop request is honoured within 50 ms.
  while (std::chrono::steady_clock::now() < end && !(stop_ != nullptr && stop_->load())) {
    std::this_thread::sleep_for(std::min<std::chrono::steady_clock::duration>(std::chrono::milliseconds(50),
                                                                               end - std::chrono::steady_clock::now()));
  }
  return trace;
}

}  // namespace surfmap::rig
