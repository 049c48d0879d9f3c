#include "server/jobs/surface_cache.h"

#include "absl/strings/str_cat.h"
#include "server/mesh/control_mesh.h"
#include "server/mesh/plan_surface.h"

namespace surfmap {

absl::StatusOr<std::shared_ptr<const LoopSurface>> SurfaceCache::Get(int64_t object_id, int level, double site_spacing_mm) {
  const Key key{object_id, level, site_spacing_mm};
  {
    MutexLock lock(&mu_);
    // Another caller may be building it: wait for that build, then look again.
    auto not_building = [this, &key]() ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu_) { return building_.count(key) == 0; };
    mu_.Await(not_building);
    if (auto it = surfaces_.find(key); it != surfaces_.end()) {
      if (std::shared_ptr<const LoopSurface> surface = it->second.lock()) {
        KeepLocked(key, surface);
        return surface;
      }
    }
    building_[key] = 1;
  }
  absl::StatusOr<std::shared_ptr<const LoopSurface>> built = Build(object_id, level, site_spacing_mm);
  MutexLock lock(&mu_);
  building_.erase(key);
  if (built.ok()) {
    surfaces_[key] = *built;
    KeepLocked(key, *built);
  }
  return built;  // an error is returned to this caller only; the next one tries again
}

void SurfaceCache::KeepLocked(const Key& key, std::shared_ptr<const LoopSurface> surface) {
  for (auto it = recent_.begin(); it != recent_.end(); ++it) {
    if (it->first == key) {
      recent_.erase(it);
      break;
    }
  }
  recent_.emplace_front(key, std::move(surface));
  while (recent_.size() > keep_) recent_.pop_back();
  // Forget entries whose surface is gone.
  for (auto it = surfaces_.begin(); it != surfaces_.end();) {
    it = it->second.expired() ? surfaces_.erase(it) : std::next(it);
  }
}

absl::StatusOr<std::shared_ptr<const LoopSurface>> SurfaceCache::Build(int64_t object_id, int level,
                                                                       double site_spacing_mm) {
  absl::StatusOr<ObjectRecord> object = store_->GetObject(object_id, /*include_mesh=*/true);
  if (!object.ok()) return object.status();
  MeshFormat format = object->mesh_format == "ply" ? MeshFormat::kPly : MeshFormat::kObj;  // uploads store ply or obj
  absl::StatusOr<ControlMesh> mesh = ParseControlMesh(object->mesh_bytes, format, absl::StrCat("object ", object_id));
  if (!mesh.ok()) {
    return absl::DataLossError(absl::StrCat("stored mesh of object ", object_id, " no longer parses: ",
                                            mesh.status().message()));
  }
  absl::StatusOr<std::unique_ptr<LoopSurface>> derived =
      DerivedPlanSurface(*mesh, object->surface == "facets", level, site_spacing_mm);
  if (!derived.ok()) return derived.status();
  if (*derived) return std::shared_ptr<const LoopSurface>(std::move(*derived));
  absl::StatusOr<std::unique_ptr<LoopSurface>> surface = LoopSurface::Create(*mesh, level);
  if (!surface.ok()) return surface.status();
  return std::shared_ptr<const LoopSurface>(std::move(*surface));
}

}  // namespace surfmap
