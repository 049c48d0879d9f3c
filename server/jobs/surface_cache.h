// SurfaceCache: an object's Loop surface, refined once per (object, level) and
// shared by every job on it. Refining a large mesh takes long: it happens on
// the caller's thread (a pool thread), outside any job lock, and concurrent
// callers for the same surface wait for the one build instead of repeating it.
//
// Errors are not cached: an object asked for before it is uploaded (NOT_FOUND)
// is found once it exists. Surfaces are held while a job uses them, plus the
// `keep` most recently used ones (so GetMesh of an idle object stays fast);
// the rest are freed.
#pragma once

#include <cstdint>
#include <list>
#include <map>
#include <memory>
#include <utility>

#include "absl/base/thread_annotations.h"
#include "absl/status/statusor.h"
#include "server/base/mutex.h"
#include "server/mesh/loop_surface.h"
#include "storage/store.h"

namespace surfmap {

class SurfaceCache {
 public:
  explicit SurfaceCache(Store* store, size_t keep = 4) : store_(store), keep_(keep) {}

  // The object's surface refined to `level`. NOT_FOUND for an unknown object;
  // DATA_LOSS if the stored mesh does not parse (it was validated on upload).
  absl::StatusOr<std::shared_ptr<const LoopSurface>> Get(int64_t object_id, int level) ABSL_LOCKS_EXCLUDED(mu_);

 private:
  using Key = std::pair<int64_t, int>;
  absl::StatusOr<std::shared_ptr<const LoopSurface>> Build(int64_t object_id, int level);
  void KeepLocked(const Key& key, std::shared_ptr<const LoopSurface> surface) ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu_);

  Store* store_;
  const size_t keep_;
  Mutex mu_;
  std::map<Key, std::weak_ptr<const LoopSurface>> surfaces_ ABSL_GUARDED_BY(mu_);
  std::map<Key, int> building_ ABSL_GUARDED_BY(mu_);  // key -> waiting callers + 1
  std::list<std::pair<Key, std::shared_ptr<const LoopSurface>>> recent_ ABSL_GUARDED_BY(mu_);
};

}  // namespace surfmap
