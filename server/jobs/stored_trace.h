// DragTrace <-> the store's own sample struct (storage knows nothing of
// server/estimate). Phase codes: 0 forward, 1 pause, 2 reverse.
#pragma once

#include <vector>

#include "server/estimate/drag_trace.h"
#include "storage/stored_sample.h"

namespace surfmap {

std::vector<StoredSample> ToStoredSamples(const DragTrace& trace);
DragTrace FromStoredSamples(const std::vector<StoredSample>& samples);

}  // namespace surfmap
