// JobRegistry: the jobs in memory. Running and paused jobs are loaded at
// start; a finished job (completed or cancelled) is loaded when first asked
// for and kept among the `retained_finished` most recently used ones.
//
// It also restores a job after a failed write: the write's completion marks
// the runtime (needs_reload), rigs' requests that would change the job are
// refused UNAVAILABLE meanwhile (they retry), operators' state changes wait
// for the re-read (DeferUntilReloadedLocked), and the job is re-read from the store behind a
// barrier through the store's write queue (Store::SyncAsync), so the re-read
// sees every write queued before it.
#pragma once

#include <cstdint>
#include <list>
#include <map>
#include <memory>

#include "absl/base/thread_annotations.h"
#include "absl/status/statusor.h"
#include "server/base/mutex.h"
#include "server/jobs/command_lookahead.h"
#include "server/jobs/job_executors.h"
#include "server/jobs/job_runtime.h"
#include "server/jobs/surface_cache.h"
#include "storage/store.h"

namespace surfmap {

class JobRegistry {
 public:
  JobRegistry(Store* store, JobExecutors executors, size_t retained_finished = 8);

  // Loads every running or paused job (refines their surfaces: long).
  absl::Status LoadActiveJobs() ABSL_LOCKS_EXCLUDED(mu_);

  // The job if it is in memory (cheap: any thread).
  std::shared_ptr<JobRuntime> Find(int64_t job_id) ABSL_LOCKS_EXCLUDED(mu_);
  // The job, loading it from the store if needed: long work (a pool thread).
  // NOT_FOUND for an unknown job.
  absl::StatusOr<std::shared_ptr<JobRuntime>> Get(int64_t job_id) ABSL_LOCKS_EXCLUDED(mu_);
  // A job just created.
  void Add(std::shared_ptr<JobRuntime> runtime) ABSL_LOCKS_EXCLUDED(mu_);
  // The job reached a final state: it may be dropped from memory later.
  void NoteFinished(int64_t job_id) ABSL_LOCKS_EXCLUDED(mu_);

  // A write that changed `runtime` in memory failed with `failed` (from a
  // completion): starts the re-read and returns what the caller should answer.
  // A write queued behind an earlier failed one is refused by the store's
  // plan-revision guard (ABORTED) through no fault of its sender: it is
  // answered UNAVAILABLE, since a retry after the re-read succeeds.
  absl::Status MarkWriteFailed(JobRuntime& runtime, const absl::Status& failed) ABSL_LOCKS_EXCLUDED(runtime.mu);
  // Under runtime.mu, before a request changes the job: UNAVAILABLE (and a
  // reload started) while the job waits to be re-read after a failed write.
  absl::Status CheckWritableLocked(JobRuntime& runtime) ABSL_EXCLUSIVE_LOCKS_REQUIRED(runtime.mu);
  // Under runtime.mu, while CheckWritableLocked would refuse: runs `then` on
  // the completion executor once the job has been re-read (OK), or the
  // re-read failed (UNAVAILABLE saying why). Never blocks.
  void DeferUntilReloadedLocked(JobRuntime& runtime, std::function<void(absl::Status reloaded)> then)
      ABSL_EXCLUSIVE_LOCKS_REQUIRED(runtime.mu);
  // CheckWritableLocked, and FAILED_PRECONDITION once the job is finished:
  // "job 7 is cancelled: it takes no more <answers>" (traces, failure
  // reports, imported traces: every answer that changes the plan).
  absl::Status CheckTakesAnswersLocked(JobRuntime& runtime, const char* answers)
      ABSL_EXCLUSIVE_LOCKS_REQUIRED(runtime.mu);

  SurfaceCache& surfaces() { return surfaces_; }
  // How many commands every job keeps issued ahead of its answers.
  CommandLookahead& lookahead() { return lookahead_; }
  size_t loaded_jobs() ABSL_LOCKS_EXCLUDED(mu_);

 private:
  absl::StatusOr<std::shared_ptr<JobRuntime>> Load(const JobRecord& record);
  void StartReloadLocked(JobRuntime& runtime) ABSL_EXCLUSIVE_LOCKS_REQUIRED(runtime.mu);
  void Reload(const std::shared_ptr<JobRuntime>& runtime);
  void TouchFinishedLocked(int64_t job_id) ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu_);

  Store* const store_;
  const JobExecutors executors_;
  const size_t retained_finished_;
  SurfaceCache surfaces_;
  CommandLookahead lookahead_;
  Mutex mu_;
  std::map<int64_t, std::shared_ptr<JobRuntime>> jobs_ ABSL_GUARDED_BY(mu_);
  std::list<int64_t> finished_ ABSL_GUARDED_BY(mu_);  // loaded finished jobs, most recently used first
};

}  // namespace surfmap
