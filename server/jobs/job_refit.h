// Re-estimating every trace of a job with other estimator settings: a new fit
// version for each trace that fits (older versions stay). The traces are read
// page by page with their samples, so memory stays bounded by a page of
// traces plus one small fit record per trace, whatever the job's size; the
// new fits are written in one transaction, so a version is never half there.
// Long work: a pool thread.
#pragma once

#include <cstdint>

#include "absl/status/statusor.h"
#include "server/estimate/fit_trace.h"
#include "server/jobs/rig_registrations.h"
#include "storage/store.h"

namespace surfmap {

struct RefitOutcome {
  int32_t version = 0;
  int refitted = 0;
  int failed = 0;
};

// Traces read per page (a page of 1,000-sample traces is ~15 MB decoded).
inline constexpr int kRefitPageTraces = 256;

// `rigs`: converts traces sent in a rig's frame (their registrations from memory).
absl::StatusOr<RefitOutcome> RefitJobTraces(Store& store, const RigRegistrations& rigs, int64_t job_id,
                                            const FitOptions& options, int page_traces = kRefitPageTraces);

}  // namespace surfmap
