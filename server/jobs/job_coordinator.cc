#include "server/jobs/job_coordinator.h"

#include "absl/strings/str_cat.h"
#include "server/base/status_macros.h"
#include "server/jobs/job_watchers.h"

namespace surfmap {
namespace {

// Objects are refined this far on upload to prove the mesh is usable.
constexpr int kUploadCheckLevel = 1;

}  // namespace

JobCoordinator::JobCoordinator(Store* store, JobExecutors executors, CoordinatorOptions options)
    : store_(store),
      registry_(store, executors, options.retained_finished_jobs),
      steering_(store, &registry_, executors),
      probes_(store, &registry_, executors, options.default_lease_ms),
      reads_(store) {}

absl::StatusOr<ObjectRecord> JobCoordinator::UploadObject(const std::string& name, MeshFormat format,
                                                          std::string bytes) {
  if (name.empty() || name.size() > 200) return absl::InvalidArgumentError("object name must have 1..200 characters");
  if (bytes.empty()) return absl::InvalidArgumentError("mesh is empty (0 bytes)");
  SURFMAP_ASSIGN_OR_RETURN(ControlMesh mesh, ParseControlMesh(bytes, format, name));
  SURFMAP_RETURN_IF_ERROR(LoopSurface::Create(mesh, kUploadCheckLevel).status());
  NewObject object;
  object.name = name;
  object.mesh_format = format == MeshFormat::kPly ? "ply" : "obj";
  object.mesh_bytes = std::move(bytes);
  object.control_vertices = static_cast<int64_t>(mesh.positions.size());
  object.control_faces = static_cast<int64_t>(mesh.triangles.size());
  SURFMAP_ASSIGN_OR_RETURN(int64_t id, store_->CreateObject(object));
  return store_->GetObject(id, /*include_mesh=*/false);
}

absl::StatusOr<std::shared_ptr<const LoopSurface>> JobCoordinator::Surface(int64_t object_id, int level) {
  if (level < 0 || level > 6) return absl::InvalidArgumentError(absl::StrCat("level must be in 0..6, got ", level));
  return registry_.surfaces().Get(object_id, level);
}

absl::StatusOr<std::shared_ptr<const LoopSurface>> JobCoordinator::JobSurface(int64_t job_id) {
  SURFMAP_ASSIGN_OR_RETURN(std::shared_ptr<JobRuntime> runtime, registry_.Get(job_id));
  return runtime->surface;
}

absl::StatusOr<MapSnapshot> JobCoordinator::Map(int64_t job_id) {
  SURFMAP_ASSIGN_OR_RETURN(std::shared_ptr<JobRuntime> runtime, registry_.Get(job_id));
  return CurrentMap(*runtime);
}

absl::StatusOr<JobCoordinator::WatchHandle> JobCoordinator::Watch(int64_t job_id, std::function<void()> listener) {
  SURFMAP_ASSIGN_OR_RETURN(std::shared_ptr<JobRuntime> runtime, registry_.Get(job_id));
  const int64_t id = AddListener(*runtime, std::move(listener));
  return WatchHandle{std::move(runtime), id};
}

absl::StatusOr<int64_t> JobCoordinator::UpdateRevision(int64_t job_id) {
  SURFMAP_ASSIGN_OR_RETURN(std::shared_ptr<JobRuntime> runtime, registry_.Get(job_id));
  return surfmap::UpdateRevision(*runtime);
}

void JobCoordinator::Unwatch(const WatchHandle& handle) {
  if (handle.runtime) RemoveListener(*handle.runtime, handle.listener);
}

}  // namespace surfmap
