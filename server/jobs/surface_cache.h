// SurfaceCache: an object's Loop surface, refined once per (object, level) and
// shared by every job on it. Refining a large mesh takes long, so it happens
// once, outside any job lock.
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <utility>

#include "absl/status/statusor.h"
#include "server/mesh/loop_surface.h"
#include "storage/store.h"

namespace surfmap {

class SurfaceCache {
 public:
  explicit SurfaceCache(Store* store) : store_(store) {}

  // The object's surface refined to `level`. NOT_FOUND for an unknown object;
  // INVALID_ARGUMENT if the stored mesh does not parse (it was validated on
  // upload, so this means a damaged database).
  absl::StatusOr<std::shared_ptr<const LoopSurface>> Get(int64_t object_id, int level);

 private:
  struct Entry {
    std::once_flag once;
    absl::StatusOr<std::shared_ptr<const LoopSurface>> surface = absl::UnknownError("not built");
  };
  Store* store_;
  std::mutex mu_;
  std::map<std::pair<int64_t, int>, std::shared_ptr<Entry>> entries_;
};

}  // namespace surfmap
