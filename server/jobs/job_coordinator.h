// JobCoordinator: the service's domain logic, below gRPC. It turns requests
// into plan transitions and durable Store writes:
//
//   CreateJob      plan created; its first probe commands queued (one write)
//   LeaseCommand   the store leases the oldest ready command of a running job
//   SubmitTrace    fit -> plan.RecordFit -> new commands; trace + fit + plan +
//                  commands written in one durable transaction, then the reply
//   ReportFailure  plan.RecordFailure -> retry command or failed site (one write)
//
// The plan in memory runs ahead of the database only between a write being
// queued and it becoming durable; writes of one job are queued in order under
// the job's lock and the store commits them in queue order, so the stored plan
// is always a state the plan really passed through. If a write fails the job is
// reloaded from the database before its next use.
//
// Thread-safe. Callbacks may run on the store's writer thread: they must not
// block.
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "server/estimate/drag_trace.h"
#include "server/estimate/fit_trace.h"
#include "server/jobs/job_params.h"
#include "server/jobs/job_runtime.h"
#include "server/jobs/surface_cache.h"
#include "server/mesh/control_mesh.h"
#include "server/plan/plan_journal.h"
#include "storage/store.h"

namespace surfmap {

struct JobSnapshot {
  JobRecord record;   // updated_unix_ms: the job's last change (JobRuntime::updated_unix_ms)
  JobParams params;
  PlanProgress progress;
  // Commands leased to a rig with an unexpired lease (at most progress.issued);
  // counted from the store only by CreateJob, GetJob, ListJobs, SetJobState.
  std::optional<LeasedCounts> leased;
  std::shared_ptr<const AcceptedSample> latest_sample;  // null before the first trace
};

struct LeaseOutcome {
  std::optional<CommandRecord> record;
  std::optional<ProbeCommand> command;  // decoded record->command_json
  bool job_finished = false;            // the requested job is completed or cancelled
  int64_t retry_after_ms = 0;           // when nothing is ready
};

struct SubmitOutcome {
  CommandRecord command;
  ProbeCommand probe;
  int64_t trace_id = 0;
  FitRecord fit;
  bool already_accepted = false;
  PlanProgress progress;
  std::optional<LeaseOutcome> next;  // when the submission asked to lease the next command
  std::shared_ptr<const TraceFit> decoded_fit;  // fit.result_json decoded; null for a retry
};

struct RefitOutcome {
  int32_t version = 0;
  int refitted = 0;
  int failed = 0;
};

class JobCoordinator {
 public:
  JobCoordinator(Store* store, int64_t default_lease_ms);

  // Rebuilds every running or paused job from the database.
  absl::Status LoadJobs();

  // Objects. The mesh is parsed, validated and refined to level 1 before it is
  // stored, so a stored object always has a usable surface.
  absl::StatusOr<ObjectRecord> UploadObject(const std::string& name, MeshFormat format, std::string bytes);
  absl::StatusOr<std::shared_ptr<const LoopSurface>> Surface(int64_t object_id, int level);

  // Jobs.
  absl::StatusOr<JobSnapshot> CreateJob(const JobParams& params);
  absl::StatusOr<JobSnapshot> GetJob(int64_t job_id);
  absl::StatusOr<std::vector<JobSnapshot>> ListJobs(int64_t object_id);
  absl::StatusOr<JobSnapshot> SetJobState(int64_t job_id, JobState target);
  absl::StatusOr<std::vector<SiteRecord>> PlanSites(int64_t job_id, PlanProgress* progress);
  // Commands of the job leased to a rig whose lease has not expired, in all
  // and per level, each at most the `progress` snapshot's issued count (one
  // store read: not for the trace path). Read it after taking `progress`: a
  // command whose trace is being written is still leased in the store while
  // the plan already counts it measured.
  absl::StatusOr<LeasedCounts> LeasedCommands(int64_t job_id, const PlanProgress& progress);

  // Probing.
  using LeaseCallback = std::function<void(absl::StatusOr<LeaseOutcome>)>;
  void LeaseCommand(const std::string& rig_id, int64_t job_id, LeaseCallback done);
  using SubmitCallback = std::function<void(absl::StatusOr<SubmitOutcome>)>;
  // lease_next: also lease this rig's next command of the same job in the
  // same durable write (outcome.next), saving the rig a round trip.
  void SubmitTrace(int64_t command_id, const std::string& rig_id, DragTrace trace, bool lease_next,
                   SubmitCallback done);
  using FailureCallback = std::function<void(absl::StatusOr<bool>)>;  // will the site be retried?
  void ReportFailure(int64_t command_id, const std::string& rig_id, const std::string& reason,
                     FailureCallback done);

  // Estimates and the map.
  absl::StatusOr<MapSnapshot> Map(int64_t job_id);
  absl::StatusOr<RefitOutcome> RefitJob(int64_t job_id, const FitOptions& options);

  // Watchers: `listener` is called (without locks held, possibly on the
  // writer thread) after every change of the job. Returns a handle for Unwatch.
  absl::StatusOr<int64_t> Watch(int64_t job_id, std::function<void()> listener);
  void Unwatch(int64_t job_id, int64_t handle);
  // The job's update revision (increases with every change).
  absl::StatusOr<int64_t> UpdateRevision(int64_t job_id);

  Store* store() { return store_; }

 private:
  absl::StatusOr<std::shared_ptr<JobRuntime>> Runtime(int64_t job_id);
  absl::StatusOr<std::shared_ptr<JobRuntime>> LoadRuntime(const JobRecord& record);
  // Under runtime->mu: reload the plan from the database if a write failed.
  absl::Status ReloadIfNeeded(JobRuntime& runtime);
  JobSnapshot SnapshotLocked(JobRuntime& runtime, const JobRecord& record);
  // Sets snapshot.leased from the store; call without the job's lock.
  absl::Status AddLeasedCount(JobSnapshot& snapshot);
  static void Notify(const std::shared_ptr<JobRuntime>& runtime);
  // A command, its decoded probe and its job's runtime.
  struct CommandContext {
    CommandRecord record;
    ProbeCommand probe;
    std::shared_ptr<JobRuntime> runtime;
  };
  absl::StatusOr<CommandContext> LoadCommandContext(int64_t command_id);
  // What one answer (`change`, already applied to runtime.plan) writes to the
  // store: a journal entry, or a checkpoint of the whole plan every
  // CheckpointInterval entries and when the plan completes.
  struct PlanWrite {
    std::string checkpoint_json;
    std::string journal_entry;
    int64_t expected_revision = 0;
    std::vector<NewCommand> new_commands;
    std::optional<JobState> new_job_state;

    // Into an AcceptTraceRequest or a FailCommandRequest (same field names).
    template <typename Request>
    void MoveInto(Request& request) && {
      request.new_plan_json = std::move(checkpoint_json);
      request.plan_journal_entry = std::move(journal_entry);
      request.expected_plan_revision = expected_revision;
      request.new_commands = std::move(new_commands);
      request.new_job_state = new_job_state;
    }
  };
  // Under runtime.mu, after the plan changed: the new commands it issues, its
  // stored form, the revision the write must find, and completion of the job.
  static PlanWrite TakePlanChangeLocked(JobRuntime& runtime, const PlanJournalEntry& change);
  void MarkWriteFailed(const std::shared_ptr<JobRuntime>& runtime);

  Store* store_;
  int64_t default_lease_ms_;
  SurfaceCache surfaces_;
  std::mutex mu_;
  std::map<int64_t, std::shared_ptr<JobRuntime>> jobs_;
};

// Unix milliseconds now (system clock).
int64_t UnixMillisNow();

}  // namespace surfmap
