// The map of a job's measured drags (every piece along its path, regions of
// like texture with explicit boundaries: server/map/region_map.h) on the
// job's map level, rebuilt when new fits arrived and cached per job.
// Building it is long work (graph searches and a sparse solve over the level):
// call from a pool thread. Concurrent callers for the same job share one
// rebuild (they wait for it on the job's map lock, which is never held
// together with anything a rig needs).
#pragma once

#include "absl/status/statusor.h"
#include "server/jobs/job_runtime.h"

namespace surfmap {

absl::StatusOr<MapSnapshot> CurrentMap(JobRuntime& runtime) ABSL_LOCKS_EXCLUDED(runtime.map_mu, runtime.mu);

}  // namespace surfmap
