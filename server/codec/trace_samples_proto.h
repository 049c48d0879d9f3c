// A drag trace <-> the API's columnar TraceSamples message: one conversion for
// the server, the CLI, the rig client and the tests.
#pragma once

#include <limits>

#include "absl/status/statusor.h"
#include "proto/surfmap/v1/surfmap.pb.h"
#include "server/estimate/drag_trace.h"

namespace surfmap {

// Columns must have equal lengths, 1..max_samples rows (RESOURCE_EXHAUSTED
// beyond), phases not UNSPECIFIED (INVALID_ARGUMENT naming the column or
// sample); values are checked by FitTrace (and the CSV reader) later.
absl::StatusOr<DragTrace> DragTraceFromProto(const ::surfmap::v1::TraceSamples& samples,
                                             int max_samples = std::numeric_limits<int>::max());
::surfmap::v1::TraceSamples DragTraceToProto(const DragTrace& trace);

}  // namespace surfmap
