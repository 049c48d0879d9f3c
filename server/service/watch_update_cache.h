// The updates of WatchJob streams, built once per job change and shared by
// every stream of the job that asks for the same thing (with or without the
// map): four dashboards on one job cost one map rebuild and one message, not
// four. gRPC serializes a shared message for each stream; nothing is copied.
//
// Keyed by (job, include_map) and the job's update revision (bumped with
// every change watchers see). Builds run on the caller's pool thread; a
// second caller for the same key waits for the build under way instead of
// repeating it.
#pragma once

#include <cstdint>
#include <list>
#include <map>
#include <memory>
#include <utility>

#include "absl/base/thread_annotations.h"
#include "absl/status/statusor.h"
#include "server/base/mutex.h"
#include "server/jobs/job_coordinator.h"
#include "server/service/proto_builders.h"

namespace surfmap {

struct SharedUpdate {
  std::shared_ptr<const pb::JobUpdate> update;
  bool final = false;  // the job has ended: the last update of a stream
};

class WatchUpdateCache {
 public:
  explicit WatchUpdateCache(JobCoordinator* coordinator, size_t capacity = 64)
      : coordinator_(coordinator), capacity_(capacity) {}

  // The job's update as of now (long work on a miss: a pool thread).
  absl::StatusOr<SharedUpdate> Get(int64_t job_id, bool include_map) ABSL_LOCKS_EXCLUDED(mu_);

 private:
  using Key = std::pair<int64_t, bool>;
  struct Entry {
    int64_t revision = -1;
    SharedUpdate built;
    bool building = false;
  };
  absl::StatusOr<SharedUpdate> Build(int64_t job_id, bool include_map);
  // The key's entry, made (and the oldest evicted) if new.
  Entry& EntryLocked(const Key& key) ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu_);

  JobCoordinator* const coordinator_;
  const size_t capacity_;
  Mutex mu_;
  std::map<Key, Entry> entries_ ABSL_GUARDED_BY(mu_);
  std::list<Key> order_ ABSL_GUARDED_BY(mu_);  // oldest first, for eviction
};

}  // namespace surfmap
