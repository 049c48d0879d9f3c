#include "server/jobs/job_map.h"

#include <vector>

namespace surfmap {

absl::StatusOr<MapSnapshot> CurrentMap(JobRuntime& runtime) {
  MutexLock map_lock(&runtime.map_mu);
  int64_t revision;
  std::vector<MapSample> samples;
  {
    MutexLock lock(&runtime.mu);
    revision = runtime.measured_revision;
    if (runtime.map_snapshot.surface && runtime.map_snapshot.measured_revision == revision) {
      return runtime.map_snapshot;
    }
    samples = runtime.plan.MeasuredSamples();
  }
  // The rebuild runs without the job's lock: rigs go on meanwhile.
  if (!runtime.map_builder) {
    absl::StatusOr<FrictionMap> builder = FrictionMap::Create(runtime.surface->finest());
    if (!builder.ok()) return builder.status();
    runtime.map_builder.emplace(std::move(*builder));
  }
  MapSnapshot snapshot;
  snapshot.surface = runtime.surface;
  snapshot.measured_revision = revision;
  if (!samples.empty()) {
    if (absl::Status s = runtime.map_builder->SetSamples(std::move(samples)); !s.ok()) return s;
    snapshot.map = std::make_shared<const FrictionMap>(*runtime.map_builder);
  }
  runtime.map_snapshot = snapshot;
  return snapshot;
}

}  // namespace surfmap
