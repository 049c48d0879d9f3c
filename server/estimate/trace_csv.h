// Drag-trace CSV: a strict reader and a round-tripping writer (no file I/O).
//
// Format (docs/trace-format.md): a header line naming the columns t,x,y,z,fx,fy,fz,phase
// (exactly these eight names, in any order), then one sample per line. Lines
// whose first non-blank character is '#' and blank lines are skipped anywhere.
// Units: t in s, positions in mm, forces in N (by the surface on the probe).
// phase is fwd, pause or rev; forward samples come first, then the optional
// pause, then the reverse pass.
#pragma once

#include <string>
#include <string_view>

#include "absl/status/statusor.h"
#include "server/estimate/drag_trace.h"

namespace surfmap {

// Parses `text`. Every malformed or meaningless input is rejected with
// INVALID_ARGUMENT and a message "<source>:<line>: <problem>" (line numbers are
// 1-based): missing header or column, unknown or duplicate column, wrong field
// count, text where a number belongs (the whole field must parse), NaN or
// infinity, time that does not increase, unknown phase, phases out of order,
// no forward or no reverse pass. Physical checks that need the whole trace
// (too few samples for a fit, zero force, a reverse pass that does not retrace
// the forward one) are FitTrace's job.
absl::StatusOr<DragTrace> ParseTraceCsv(std::string_view text, std::string_view source);

// Writes the header and one line per sample with the shortest representation
// that reads back to the same double, so ParseTraceCsv(FormatTraceCsv(t))
// reproduces t exactly. Does not validate.
std::string FormatTraceCsv(const DragTrace& trace);

}  // namespace surfmap
