// Creating jobs, reading their state, and steering them (pause, resume,
// cancel). A state change is decided under the job's lock, queued to the
// store without waiting, and applied to what the job reports once durable.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <vector>

#include "absl/status/statusor.h"
#include "server/jobs/job_executors.h"
#include "server/jobs/job_params.h"
#include "server/jobs/job_registry.h"
#include "server/jobs/job_runtime.h"
#include "storage/store.h"

namespace surfmap {

struct JobSnapshot {
  // record.state: the state as stored (a change being written shows once it
  // is durable); record.updated_unix_ms: the job's last change.
  JobRecord record;
  JobParams params;
  // The plan in memory: a site whose trace is being written counts as measured.
  PlanProgress progress;
  // Commands leased to a rig with an unexpired lease (at most progress.issued),
  // counted from the store where the call says so.
  std::optional<LeasedCounts> leased;
  std::shared_ptr<const AcceptedSample> latest_sample;  // null before the first trace
};

class JobSteering {
 public:
  JobSteering(Store* store, JobRegistry* registry, JobExecutors executors);

  // Refines the object's surface and writes the job with its first commands
  // (waits for that write: call from a pool thread, with no lock held).
  // metadata_json: the job's provenance (provenance.h), stored with it.
  absl::StatusOr<JobSnapshot> CreateJob(const JobParams& params, const std::string& metadata_json = "{}");

  // From memory, plus one small store read for the leased counts. The job
  // must be loaded (JobRegistry::Find) unless called from a pool thread.
  absl::StatusOr<JobSnapshot> GetJob(int64_t job_id);
  // Loads finished jobs not in memory: a pool thread.
  absl::StatusOr<std::vector<JobSnapshot>> ListJobs(int64_t object_id);

  // Never waits: `done` runs once the change is durable (on the completion
  // queue or a pool thread), or at once with the refusal. While the job is
  // being re-read after a failed write the change is queued behind the
  // re-read (once), not refused: an operator's cancel is not told to retry.
  using SnapshotCallback = std::function<void(absl::StatusOr<JobSnapshot>)>;
  void SetJobState(int64_t job_id, JobState target, SnapshotCallback done);

  absl::StatusOr<std::vector<SiteRecord>> PlanSites(int64_t job_id, PlanProgress* progress);
  // Commands of the job leased now, each at most `progress`'s issued count.
  absl::StatusOr<LeasedCounts> LeasedCommands(int64_t job_id, const PlanProgress& progress);

  static JobSnapshot SnapshotLocked(JobRuntime& runtime) ABSL_EXCLUSIVE_LOCKS_REQUIRED(runtime.mu);

 private:
  absl::StatusOr<JobSnapshot> WithLeasedCount(JobSnapshot snapshot);
  // Under the job's lock: checks, moves memory, queues the write. `done` is
  // moved into the write's completion when the change is queued.
  absl::Status QueueStateChange(const std::shared_ptr<JobRuntime>& runtime, JobState target, bool may_wait,
                                SnapshotCallback& done);
  // On the completion queue, once the write finished.
  void ApplyStoredState(const std::shared_ptr<JobRuntime>& runtime, absl::StatusOr<JobRecord> stored,
                        SnapshotCallback done);

  Store* const store_;
  JobRegistry* const registry_;
  const JobExecutors executors_;
};

}  // namespace surfmap
