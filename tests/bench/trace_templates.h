// Pre-generated drag traces for the benchmark: simulated once (the drag
// simulator, all rig disturbances on) on a flat surface in a local frame,
// then placed at any probe command by a rigid motion, so the rig side of the
// benchmark costs microseconds per trace and the server does the real work.
#pragma once

#include <cstdint>
#include <vector>

#include "absl/status/statusor.h"
#include "proto/surfmap/v1/surfmap.pb.h"
#include "server/estimate/drag_trace.h"

namespace surfmap::bench {

// `count` traces of a straight `length_mm` drag from the origin along +x on
// the plane z = 0 (normal +z), sampled at `sample_rate_hz` (200 Hz and 20 mm
// give ~1,000 samples), seeds seed, seed+1, ...
absl::StatusOr<std::vector<DragTrace>> MakeTraceTemplates(int count, std::uint64_t seed, double length_mm,
                                                          double sample_rate_hz);

// The template moved to the command: origin -> position, +x -> drag
// direction, +z -> normal (positions and forces rotate together).
surfmap::v1::TraceSamples PlaceTrace(const DragTrace& local, const surfmap::v1::ProbeCommand& command);

}  // namespace surfmap::bench
