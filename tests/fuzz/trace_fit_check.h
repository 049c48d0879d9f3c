// What the trace harnesses (CSV and proto) check on a trace that a reader
// accepted: FitTrace runs without a sanitizer report, and a fit it returns
// holds only finite numbers (a NaN mu or normal would be stored and then
// poison the map), or it names the problem with INVALID_ARGUMENT.
#pragma once

#include "server/estimate/drag_trace.h"

namespace surfmap::fuzz {

// Traces with more samples than this are not fitted: FitTrace is O(n) but
// costs ~0.1 ms per 1000 samples under the sanitizers, and length beyond a few
// hundred samples reaches no new code.
inline constexpr std::size_t kMaxFittedSamples = 4096;

// Fits `trace` with the default options and with the least-squares AR method
// (the two roughness solvers), checking each result as described above.
// Returns true when at least one fit succeeded.
bool FitAndCheck(const DragTrace& trace);

// Bitwise equality of every sample (so -0.0 != 0.0, as a round trip must keep it).
bool SameTrace(const DragTrace& a, const DragTrace& b);

}  // namespace surfmap::fuzz
