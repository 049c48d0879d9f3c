#include "server/jobs/job_coordinator.h"

#include "absl/strings/str_cat.h"
#include "server/base/status_macros.h"
#include "server/base/utf8_text.h"
#include "server/jobs/job_watchers.h"
#include "server/mesh/facets_surface.h"
#include "server/mesh/mesh_units.h"

namespace surfmap {
namespace {

// Objects are refined this far on upload to prove the mesh is usable.
constexpr int kUploadCheckLevel = 1;

}  // namespace

JobCoordinator::JobCoordinator(Store* store, JobExecutors executors, CoordinatorOptions options)
    : store_(store),
      registry_(store, executors, options.retained_finished_jobs),
      rigs_(store),
      steering_(store, &registry_, executors),
      probes_(store, &registry_, &rigs_, executors, options.default_lease_ms),
      imports_(store, &registry_, executors),
      reads_(store, &rigs_) {}

absl::StatusOr<ObjectRecord> JobCoordinator::UploadObject(const std::string& name, MeshFormat format,
                                                          std::string bytes) {
  SURFMAP_ASSIGN_OR_RETURN(UploadedObject uploaded, UploadObject(name, format, std::move(bytes), UploadOptions{}));
  return std::move(uploaded.object);
}

absl::StatusOr<UploadedObject> JobCoordinator::UploadObject(const std::string& name, MeshFormat format,
                                                            std::string bytes, const UploadOptions& options) {
  return UploadObject(name, format, std::move(bytes), options, Provenance{});
}

absl::StatusOr<UploadedObject> JobCoordinator::UploadObject(const std::string& name, MeshFormat format,
                                                            std::string bytes, const UploadOptions& options,
                                                            const Provenance& provenance) {
  SURFMAP_RETURN_IF_ERROR(ValidateProvenance(provenance));
  // Characters, not bytes: "瓶" is one character of three bytes.
  SURFMAP_RETURN_IF_ERROR(ValidateName("object name", name, 1, 200));
  if (bytes.empty()) return absl::InvalidArgumentError("mesh is empty (0 bytes)");
  SURFMAP_ASSIGN_OR_RETURN(RepairedMesh repaired, ParseAndRepairMesh(bytes, format, name, options.mm_per_unit));
  const ControlMesh& mesh = repaired.mesh;
  UploadedObject out;
  out.mm_per_unit = options.mm_per_unit;
  out.extent_mm = BoundingBoxSize(mesh);
  out.area_mm2 = SurfaceArea(mesh);
  out.repairs = std::move(repaired.repairs);
  if (options.unit_stated) {
    SURFMAP_RETURN_IF_ERROR(CheckObjectSize(out.extent_mm, options.unit_text, &out.warnings));
  } else {
    // Uploads from before units existed are taken as mm, as they always were;
    // an implausible size is only a warning for them.
    std::vector<std::string> size_warnings;
    const absl::Status plausible = CheckObjectSize(out.extent_mm, "mm (units not given)", &size_warnings);
    if (!plausible.ok()) out.warnings.emplace_back(plausible.message());
    for (std::string& w : size_warnings) out.warnings.push_back(std::move(w));
  }
  if (options.facets) {
    SURFMAP_RETURN_IF_ERROR(ExactFacetsSurface(mesh, kUploadCheckLevel).status());
  } else {
    SURFMAP_RETURN_IF_ERROR(LoopSurface::Create(mesh, kUploadCheckLevel).status());
  }
  NewObject object;
  object.name = name;
  object.metadata_json = MetadataJsonOf(provenance);
  object.surface = options.facets ? "facets" : "control_mesh";
  // A clean file in mm is stored as it came; anything changed is stored as
  // the repaired mesh in mm (OBJ, coordinates exact: shortest round trip).
  if (out.repairs.empty() && options.mm_per_unit == 1.0 && format != MeshFormat::kStl) {
    object.mesh_format = format == MeshFormat::kPly ? "ply" : "obj";
    object.mesh_bytes = std::move(bytes);
  } else {
    object.mesh_format = "obj";
    object.mesh_bytes = WriteObj(mesh);
  }
  object.control_vertices = static_cast<int64_t>(mesh.positions.size());
  object.control_faces = static_cast<int64_t>(mesh.triangles.size());
  SURFMAP_ASSIGN_OR_RETURN(int64_t id, store_->CreateObject(object));
  SURFMAP_ASSIGN_OR_RETURN(out.object, store_->GetObject(id, /*include_mesh=*/false));
  return out;
}

absl::StatusOr<std::shared_ptr<const LoopSurface>> JobCoordinator::Surface(int64_t object_id, int level,
                                                                           double site_spacing_mm) {
  if (level < 0 || level > 6) return absl::InvalidArgumentError(absl::StrCat("level must be in 0..6, got ", level));
  return registry_.surfaces().Get(object_id, level, site_spacing_mm);
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
