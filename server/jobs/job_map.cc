#include "server/jobs/job_map.h"

#include <vector>

namespace surfmap {

absl::StatusOr<MapSnapshot> CurrentMap(JobRuntime& runtime) {
  MutexLock map_lock(&runtime.map_mu);
  int64_t revision;
  std::vector<MapPiece> pieces;
  int first_import_drag = 0;
  {
    MutexLock lock(&runtime.mu);
    revision = runtime.measured_revision;
    if (runtime.map_snapshot.surface && runtime.map_snapshot.measured_revision == revision) {
      return runtime.map_snapshot;
    }
    pieces = runtime.plan.MeasuredPieces();
    first_import_drag = runtime.plan.FirstImportDrag();
  }
  // The rebuild runs without the job's lock: rigs go on meanwhile.
  if (!runtime.map_builder) {
    absl::StatusOr<RegionMap> builder = RegionMap::Create(runtime.surface->finest());
    if (!builder.ok()) return builder.status();
    runtime.map_builder.emplace(std::move(*builder));
  }
  MapSnapshot snapshot;
  snapshot.surface = runtime.surface;
  snapshot.measured_revision = revision;
  snapshot.first_import_drag = first_import_drag;
  if (!pieces.empty()) {
    if (absl::Status s = runtime.map_builder->SetPieces(std::move(pieces)); !s.ok()) return s;
    // The copy shares the builder's factorisation workspace, which only
    // SetPieces (here, under map_mu) uses; its const reads are independent.
    snapshot.map = std::make_shared<const RegionMap>(*runtime.map_builder);
  }
  runtime.map_snapshot = snapshot;
  return snapshot;
}

}  // namespace surfmap
