#include "server/jobs/job_steering.h"

#include <algorithm>

#include "absl/strings/str_cat.h"
#include "server/base/status_macros.h"
#include "server/jobs/job_watchers.h"
#include "server/jobs/record_conversion.h"

namespace surfmap {

JobSteering::JobSteering(Store* store, JobRegistry* registry, JobExecutors executors)
    : store_(store), registry_(registry), executors_(executors) {}

JobSnapshot JobSteering::SnapshotLocked(JobRuntime& runtime) {
  JobSnapshot s;
  s.record.id = runtime.job_id;
  s.record.object_id = runtime.object_id;
  s.record.state = runtime.durable_state;
  s.record.created_unix_ms = runtime.created_unix_ms;
  s.record.updated_unix_ms = runtime.updated_unix_ms;
  s.record.metadata_json = runtime.metadata_json;
  s.params = runtime.params;
  s.progress = runtime.plan.Progress();
  s.latest_sample = runtime.latest_sample;
  return s;
}

absl::StatusOr<LeasedCounts> JobSteering::LeasedCommands(int64_t job_id, const PlanProgress& progress) {
  SURFMAP_ASSIGN_OR_RETURN(LeasedCounts leased, store_->CountLeasedCommands(job_id, UnixMillisNow()));
  // Read after the plan's snapshot: a command whose trace is being written is
  // still leased in the store while the plan already counts it measured.
  LeasedCounts clamped;
  clamped.total = std::min(leased.total, progress.issued);
  for (const LevelProgress& level : progress.levels) {
    auto it = leased.by_level.find(level.level);
    if (it != leased.by_level.end()) clamped.by_level[level.level] = std::min(it->second, level.issued);
  }
  return clamped;
}

absl::StatusOr<JobSnapshot> JobSteering::WithLeasedCount(JobSnapshot snapshot) {
  SURFMAP_ASSIGN_OR_RETURN(snapshot.leased, LeasedCommands(snapshot.record.id, snapshot.progress));
  return snapshot;
}

absl::StatusOr<JobSnapshot> JobSteering::CreateJob(const JobParams& requested, const std::string& metadata_json) {
  JobParams params = requested;
  if (params.finest_level == kAutoLevel || params.map_level == kAutoLevel) {
    SURFMAP_ASSIGN_OR_RETURN(std::shared_ptr<const LoopSurface> control,
                             registry_->surfaces().Get(params.object_id, 0, params.site_spacing_mm));
    ResolveAutoLevels(control->level(0), params);
  }
  std::string why;
  if (!params.IsValid(&why)) return absl::InvalidArgumentError("job: " + why);
  SURFMAP_ASSIGN_OR_RETURN(std::shared_ptr<const LoopSurface> surface,
                           registry_->surfaces().Get(params.object_id, params.map_level, params.site_spacing_mm));
  SURFMAP_ASSIGN_OR_RETURN(SamplingPlan plan,
                           SamplingPlan::Create(JobPlanLevels(*surface, params), PlanOptionsFor(params)));
  NewJob job;
  job.object_id = params.object_id;
  job.params_json = JobParamsToJson(params).dump();
  job.metadata_json = metadata_json;
  job.commands = DrainCommands(plan, registry_->lookahead().CommandsAhead(UnixMillisNow()));
  job.plan_json = plan.SaveJson();
  job.events.push_back(Event("job_created", {{"initial_commands", job.commands.size()}}));
  SURFMAP_ASSIGN_OR_RETURN(CreatedJob created, store_->CreateJob(job));

  auto runtime = std::make_shared<JobRuntime>(created.job.id, params.object_id, params, std::move(surface),
                                              std::move(plan), created.job.created_unix_ms);
  runtime->metadata_json = metadata_json;
  JobSnapshot snapshot;
  {
    MutexLock lock(&runtime->mu);
    runtime->updated_unix_ms = created.job.updated_unix_ms;
    snapshot = SnapshotLocked(*runtime);
  }
  registry_->Add(runtime);
  snapshot.leased = LeasedCounts{};  // nothing can have been leased yet
  return snapshot;
}

absl::StatusOr<JobSnapshot> JobSteering::GetJob(int64_t job_id) {
  SURFMAP_ASSIGN_OR_RETURN(std::shared_ptr<JobRuntime> runtime, registry_->Get(job_id));
  JobSnapshot snapshot;
  {
    MutexLock lock(&runtime->mu);
    snapshot = SnapshotLocked(*runtime);
  }
  return WithLeasedCount(std::move(snapshot));
}

absl::StatusOr<std::vector<JobSnapshot>> JobSteering::ListJobs(int64_t object_id) {
  SURFMAP_ASSIGN_OR_RETURN(std::vector<JobRecord> records, store_->ListJobs(object_id));
  std::vector<JobSnapshot> out;
  out.reserve(records.size());
  for (const JobRecord& record : records) {
    SURFMAP_ASSIGN_OR_RETURN(JobSnapshot snapshot, GetJob(record.id));
    out.push_back(std::move(snapshot));
  }
  return out;
}

void JobSteering::SetJobState(int64_t job_id, JobState target, SnapshotCallback done) {
  std::shared_ptr<JobRuntime> runtime = registry_->Find(job_id);
  if (!runtime) {
    // Not in memory: only finished jobs are not, and they take no change.
    absl::StatusOr<JobRecord> record = store_->GetJob(job_id);
    if (!record.ok()) return done(record.status());
    return done(absl::FailedPreconditionError(absl::StrCat("job ", job_id, " is ",
                                                           std::string(JobStateName(record->state)),
                                                           "; cannot become ", std::string(JobStateName(target)))));
  }
  absl::Status refused = QueueStateChange(runtime, target, /*may_wait=*/true, done);
  if (!refused.ok()) done(refused);  // after the job's lock is released
}

absl::Status JobSteering::QueueStateChange(const std::shared_ptr<JobRuntime>& runtime, JobState target, bool may_wait,
                                           SnapshotCallback& done) {
  MutexLock lock(&runtime->mu);
  if (runtime->needs_reload && may_wait) {
    registry_->DeferUntilReloadedLocked(
        *runtime, [this, runtime, target, done = std::move(done)](absl::Status reloaded) mutable {
          if (!reloaded.ok()) return done(reloaded);
          absl::Status refused = QueueStateChange(runtime, target, /*may_wait=*/false, done);
          if (!refused.ok()) done(refused);
        });
    return absl::OkStatus();
  }
  SURFMAP_RETURN_IF_ERROR(registry_->CheckWritableLocked(*runtime));
  const JobState from = runtime->state;
  if (!IsJobTransitionAllowed(from, target)) {
    return absl::FailedPreconditionError(absl::StrCat("job ", runtime->job_id, " is ", std::string(JobStateName(from)),
                                                      "; cannot become ", std::string(JobStateName(target))));
  }
  // Decided: memory moves now, so the next request is checked against this
  // state; the write is queued (never awaited) in order with every other
  // write of the job, so the database passes through the same states.
  runtime->state = target;
  if (target == JobState::kCancelled) runtime->plan.Cancel();
  JobStateChange change{runtime->job_id, target,
                        {Event("job_state", {{"from", std::string(JobStateName(from))},
                                             {"to", std::string(JobStateName(target))}})}};
  store_->UpdateJobStateAsync(std::move(change), [this, runtime, done = std::move(done)](
                                                     absl::StatusOr<JobRecord> stored) mutable {
    executors_.completions->Post([this, runtime, stored = std::move(stored), done = std::move(done)]() mutable {
      ApplyStoredState(runtime, std::move(stored), std::move(done));
    });
  });
  return absl::OkStatus();
}

void JobSteering::ApplyStoredState(const std::shared_ptr<JobRuntime>& runtime, absl::StatusOr<JobRecord> stored,
                                   SnapshotCallback done) {
  if (!stored.ok()) {
    return done(registry_->MarkWriteFailed(*runtime, stored.status()));
  }
  JobSnapshot snapshot;
  {
    MutexLock lock(&runtime->mu);
    runtime->durable_state = stored->state;
    runtime->updated_unix_ms = std::max(runtime->updated_unix_ms, stored->updated_unix_ms);
    snapshot = SnapshotLocked(*runtime);
  }
  if (IsFinalJobState(stored->state)) registry_->NoteFinished(runtime->job_id);
  NotifyListeners(*runtime);
  // The leased count is a store read: not on the completion queue, and not
  // on the long-work pool either, where a steering answer would wait behind
  // map builds (three watchers of a 1 mm map kept both of its threads busy
  // for seconds under TSan, and a pause missed its 5 s deadline).
  executors_.probes->Post([this, snapshot = std::move(snapshot), done = std::move(done)]() mutable {
    done(WithLeasedCount(std::move(snapshot)));
  });
}

absl::StatusOr<std::vector<SiteRecord>> JobSteering::PlanSites(int64_t job_id, PlanProgress* progress) {
  SURFMAP_ASSIGN_OR_RETURN(std::shared_ptr<JobRuntime> runtime, registry_->Get(job_id));
  MutexLock lock(&runtime->mu);
  *progress = runtime->plan.Progress();
  return runtime->plan.Sites();
}

}  // namespace surfmap
