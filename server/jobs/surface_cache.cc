#include "server/jobs/surface_cache.h"

#include "absl/strings/str_cat.h"

namespace surfmap {

absl::StatusOr<std::shared_ptr<const LoopSurface>> SurfaceCache::Get(int64_t object_id, int level) {
  std::shared_ptr<Entry> entry;
  {
    std::lock_guard<std::mutex> lock(mu_);
    auto& slot = entries_[{object_id, level}];
    if (!slot) slot = std::make_shared<Entry>();
    entry = slot;
  }
  std::call_once(entry->once, [&] {
    absl::StatusOr<ObjectRecord> object = store_->GetObject(object_id, /*include_mesh=*/true);
    if (!object.ok()) {
      entry->surface = object.status();
      return;
    }
    MeshFormat format = object->mesh_format == "ply" ? MeshFormat::kPly : MeshFormat::kObj;
    absl::StatusOr<ControlMesh> mesh =
        ParseControlMesh(object->mesh_bytes, format, absl::StrCat("object ", object_id));
    if (!mesh.ok()) {
      entry->surface = mesh.status();
      return;
    }
    absl::StatusOr<std::unique_ptr<LoopSurface>> surface = LoopSurface::Create(*mesh, level);
    if (!surface.ok()) {
      entry->surface = surface.status();
      return;
    }
    entry->surface = std::shared_ptr<const LoopSurface>(std::move(*surface));
  });
  // A failure for an unknown object is not cached forever: the object may be
  // created later under that id only in theory (ids are never reused), so keep it.
  return entry->surface;
}

}  // namespace surfmap
