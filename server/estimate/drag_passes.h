// The three phases of a drag trace as contiguous views, after checking that the
// trace is well formed (the same rules the CSV reader applies, for traces that
// arrive by other routes, e.g. the gRPC API or the simulator).
#pragma once

#include <cstddef>
#include <span>

#include "absl/status/statusor.h"
#include "server/estimate/drag_trace.h"

namespace surfmap {

struct DragPasses {
  std::span<const DragSample> forward;
  std::span<const DragSample> pause;    // may be empty
  std::span<const DragSample> reverse;
  std::size_t pause_offset = 0;         // index of pause[0] in trace.samples
  std::size_t reverse_offset = 0;       // index of reverse[0] in trace.samples
};

// The views point into `trace`, which must outlive them. INVALID_ARGUMENT,
// naming the sample index, for: non-finite time, position or force; a position
// coordinate or force component beyond 1e9 (mm, N: the fit's arithmetic would
// overflow); time that
// does not increase; phases not in the order fwd, pause, rev; no forward or no
// reverse sample.
absl::StatusOr<DragPasses> SplitDragPasses(const DragTrace& trace);

}  // namespace surfmap
