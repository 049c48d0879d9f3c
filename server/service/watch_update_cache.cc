#include "server/service/watch_update_cache.h"

#include <algorithm>

#include "server/base/status_macros.h"
#include "server/service/proto_conversion.h"

namespace surfmap {

absl::StatusOr<SharedUpdate> WatchUpdateCache::Get(int64_t job_id, bool include_map) {
  const Key key{job_id, include_map};
  SURFMAP_ASSIGN_OR_RETURN(const int64_t revision, coordinator_->UpdateRevision(job_id));
  {
    MutexLock lock(&mu_);
    // Another stream of the job is building this update: wait for it.
    mu_.Await([this, &key]() ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu_) {
      auto it = entries_.find(key);
      return it == entries_.end() || !it->second.building;
    });
    Entry& entry = EntryLocked(key);
    if (entry.built.update && entry.revision >= revision) return entry.built;
    entry.building = true;
  }
  absl::StatusOr<SharedUpdate> built = Build(job_id, include_map);
  MutexLock lock(&mu_);
  auto it = entries_.find(key);  // evicted meanwhile: nothing to keep
  if (it != entries_.end()) {
    it->second.building = false;
    if (built.ok() && revision >= it->second.revision) {
      it->second.revision = revision;
      it->second.built = *built;
    }
  }
  return built;
}

WatchUpdateCache::Entry& WatchUpdateCache::EntryLocked(const Key& key) {
  auto it = entries_.find(key);
  if (it != entries_.end()) return it->second;
  order_.push_back(key);
  while (order_.size() > capacity_) {
    entries_.erase(order_.front());
    order_.pop_front();
  }
  return entries_[key];
}

absl::StatusOr<SharedUpdate> WatchUpdateCache::Build(int64_t job_id, bool include_map) {
  absl::StatusOr<JobSnapshot> job = coordinator_->GetJob(job_id);
  if (!job.ok()) return job.status();
  auto update = std::make_shared<pb::JobUpdate>();
  // The state is the durable one: the final update is built after the job's
  // last write committed, so the samples read below include all of it.
  *update->mutable_job() = JobInfoToProto(*job);
  SharedUpdate out;
  out.final = IsFinalJobState(job->record.state);
  if (job->latest_sample) {
    absl::StatusOr<pb::Sample> latest = BuildSample(*job->latest_sample);
    if (!latest.ok()) return latest.status();
    *update->mutable_latest_sample() = std::move(*latest);
  }
  if (include_map) {
    // An update without the map that was asked for would look like a job
    // with no samples: the stream ends with the reason instead.
    absl::StatusOr<MapSnapshot> map = coordinator_->Map(job_id);
    if (!map.ok()) return map.status();
    absl::StatusOr<std::vector<SampleRecord>> samples = coordinator_->reads().ListSamples(job_id, 0);
    if (!samples.ok()) return samples.status();
    absl::Status filled = FillMapLevel(*map, map->surface->max_level(), *samples, job_id, update->mutable_map());
    if (!filled.ok()) return filled;
  }
  out.update = std::move(update);
  return out;
}

}  // namespace surfmap
