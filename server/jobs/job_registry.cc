#include "server/jobs/job_registry.h"

#include <algorithm>

#include <nlohmann/json.hpp>
#include "absl/strings/str_cat.h"
#include "server/base/status_macros.h"
#include "server/jobs/job_watchers.h"
#include "server/jobs/stored_plan.h"

namespace surfmap {
namespace {

absl::StatusOr<JobParams> StoredParams(const JobRecord& record) {
  nlohmann::json params_json = nlohmann::json::parse(record.params_json, nullptr, false);
  if (params_json.is_discarded()) return absl::DataLossError("stored job parameters are not JSON");
  return JobParamsFromJson(params_json);
}

// The job's newest stored trace as a sample (null when it has none).
absl::StatusOr<std::shared_ptr<const AcceptedSample>> LatestSample(Store& store, int64_t job_id,
                                                                   const std::optional<TraceRecord>& trace) {
  if (!trace.has_value()) return std::shared_ptr<const AcceptedSample>();
  SURFMAP_ASSIGN_OR_RETURN(SampleRecord record, store.ReadSample(trace->id, 1, /*include_samples=*/false));
  auto sample = std::make_shared<AcceptedSample>();
  sample->command = std::move(record.command);
  sample->trace_id = record.trace.id;
  sample->fit = std::move(record.fit);
  sample->received_unix_ms = record.trace.received_unix_ms;
  sample->metadata_json = std::move(record.trace.metadata_json);
  return std::shared_ptr<const AcceptedSample>(std::move(sample));
}

}  // namespace

JobRegistry::JobRegistry(Store* store, JobExecutors executors, size_t retained_finished)
    : store_(store), executors_(executors), retained_finished_(retained_finished), surfaces_(store) {}

absl::Status JobRegistry::LoadActiveJobs() {
  SURFMAP_ASSIGN_OR_RETURN(std::vector<JobRecord> records, store_->ListActiveJobs());
  for (const JobRecord& record : records) {
    absl::StatusOr<std::shared_ptr<JobRuntime>> runtime = Load(record);
    if (!runtime.ok()) {
      return absl::Status(runtime.status().code(),
                          absl::StrCat("job ", record.id, " cannot be restored: ", runtime.status().message()));
    }
    MutexLock lock(&mu_);
    jobs_[record.id] = *runtime;
  }
  return absl::OkStatus();
}

std::shared_ptr<JobRuntime> JobRegistry::Find(int64_t job_id) {
  MutexLock lock(&mu_);
  auto it = jobs_.find(job_id);
  if (it == jobs_.end()) return nullptr;
  TouchFinishedLocked(job_id);
  return it->second;
}

absl::StatusOr<std::shared_ptr<JobRuntime>> JobRegistry::Get(int64_t job_id) {
  if (std::shared_ptr<JobRuntime> found = Find(job_id)) return found;
  if (job_id <= 0) return absl::InvalidArgumentError(absl::StrCat("job_id must be positive, got ", job_id));
  SURFMAP_ASSIGN_OR_RETURN(JobRecord record, store_->GetJob(job_id));
  SURFMAP_ASSIGN_OR_RETURN(std::shared_ptr<JobRuntime> runtime, Load(record));
  MutexLock lock(&mu_);
  auto [it, inserted] = jobs_.emplace(job_id, runtime);  // another caller may have loaded it meanwhile
  if (inserted && IsFinalJobState(record.state)) {
    finished_.push_front(job_id);
    while (finished_.size() > retained_finished_) {
      jobs_.erase(finished_.back());
      finished_.pop_back();
    }
  }
  return it->second;
}

void JobRegistry::Add(std::shared_ptr<JobRuntime> runtime) {
  MutexLock lock(&mu_);
  jobs_[runtime->job_id] = std::move(runtime);
}

void JobRegistry::NoteFinished(int64_t job_id) {
  MutexLock lock(&mu_);
  if (std::find(finished_.begin(), finished_.end(), job_id) == finished_.end()) finished_.push_front(job_id);
  while (finished_.size() > retained_finished_) {
    jobs_.erase(finished_.back());
    finished_.pop_back();
  }
}

void JobRegistry::TouchFinishedLocked(int64_t job_id) {
  auto it = std::find(finished_.begin(), finished_.end(), job_id);
  if (it != finished_.end()) finished_.splice(finished_.begin(), finished_, it);
}

size_t JobRegistry::loaded_jobs() {
  MutexLock lock(&mu_);
  return jobs_.size();
}

absl::StatusOr<std::shared_ptr<JobRuntime>> JobRegistry::Load(const JobRecord& record) {
  SURFMAP_ASSIGN_OR_RETURN(JobParams params, StoredParams(record));
  SURFMAP_ASSIGN_OR_RETURN(std::shared_ptr<const LoopSurface> surface,
                           surfaces_.Get(params.object_id, params.map_level, params.site_spacing_mm));
  SURFMAP_ASSIGN_OR_RETURN(PlanRecord plan_record, store_->GetPlan(record.id));
  SURFMAP_ASSIGN_OR_RETURN(SamplingPlan plan, RestoreStoredPlan(plan_record, JobPlanLevels(*surface, params)));
  if (record.state == JobState::kCancelled) plan.Cancel();
  // The job row's time changes only with its state; traces and failures since
  // then are newer changes, each with an event written in its transaction.
  SURFMAP_ASSIGN_OR_RETURN(JobActivity activity, store_->GetJobActivity(record.id));
  SURFMAP_ASSIGN_OR_RETURN(std::shared_ptr<const AcceptedSample> latest,
                           LatestSample(*store_, record.id, activity.latest_trace));
  auto runtime = std::make_shared<JobRuntime>(record.id, record.object_id, std::move(params), std::move(surface),
                                              std::move(plan), record.created_unix_ms);
  runtime->metadata_json = record.metadata_json;
  MutexLock lock(&runtime->mu);
  runtime->state = runtime->durable_state = record.state;
  runtime->plan_revision = plan_record.revision;
  runtime->journal_entries = static_cast<int>(plan_record.journal.size());
  runtime->measured_revision = runtime->plan.Progress().measured + runtime->plan.ImportedCount();
  runtime->updated_unix_ms = std::max(record.updated_unix_ms, activity.last_event_unix_ms.value_or(0));
  runtime->latest_sample = std::move(latest);
  return runtime;
}

absl::Status JobRegistry::MarkWriteFailed(JobRuntime& runtime, const absl::Status& failed) {
  {
    MutexLock lock(&runtime.mu);
    runtime.needs_reload = true;
    StartReloadLocked(runtime);
  }
  if (failed.code() != absl::StatusCode::kAborted) return failed;
  return absl::UnavailableError(absl::StrCat("job ", runtime.job_id,
                                             " is being re-read from the database after an earlier write failed; "
                                             "nothing of this request was stored; retry (",
                                             failed.message(), ")"));
}

absl::Status JobRegistry::CheckWritableLocked(JobRuntime& runtime) {
  if (!runtime.needs_reload) return absl::OkStatus();
  StartReloadLocked(runtime);
  return absl::UnavailableError(absl::StrCat("job ", runtime.job_id,
                                             " is being re-read from the database after a failed write; retry"));
}

void JobRegistry::DeferUntilReloadedLocked(JobRuntime& runtime, std::function<void(absl::Status reloaded)> then) {
  runtime.after_reload.push_back(std::move(then));
  StartReloadLocked(runtime);
}

absl::Status JobRegistry::CheckTakesAnswersLocked(JobRuntime& runtime, const char* answers) {
  SURFMAP_RETURN_IF_ERROR(CheckWritableLocked(runtime));
  if (!IsFinalJobState(runtime.state)) return absl::OkStatus();
  return absl::FailedPreconditionError(absl::StrCat("job ", runtime.job_id, " is ",
                                                    std::string(JobStateName(runtime.state)),
                                                    ": it takes no more ", answers));
}

void JobRegistry::StartReloadLocked(JobRuntime& runtime) {
  if (runtime.reloading) return;
  runtime.reloading = true;
  std::shared_ptr<JobRuntime> self = runtime.shared_from_this();
  // Behind the barrier every write queued before has completed; behind the
  // completion queue every earlier completion has been applied. Then the
  // re-read (long: a plan restore) runs on the pool.
  store_->SyncAsync([this, self](absl::Status) {
    executors_.completions->Post([this, self] { executors_.work->Post([this, self] { Reload(self); }); });
  });
}

void JobRegistry::Reload(const std::shared_ptr<JobRuntime>& runtime) {
  absl::StatusOr<JobRecord> record = store_->GetJob(runtime->job_id);
  absl::StatusOr<PlanRecord> plan_record = record.ok() ? store_->GetPlan(runtime->job_id)
                                                       : absl::StatusOr<PlanRecord>(record.status());
  absl::StatusOr<SamplingPlan> plan = plan_record.ok()
                                          ? RestoreStoredPlan(*plan_record, JobPlanLevels(*runtime->surface, runtime->params))
                                          : absl::StatusOr<SamplingPlan>(plan_record.status());
  std::vector<std::function<void(absl::Status)>> waiting;
  {
    MutexLock lock(&runtime->mu);
    runtime->reloading = false;
    waiting.swap(runtime->after_reload);
    if (plan.ok()) {
      runtime->plan = std::move(*plan);
      if (record->state == JobState::kCancelled) runtime->plan.Cancel();
      runtime->state = runtime->durable_state = record->state;
      runtime->plan_revision = plan_record->revision;
      runtime->journal_entries = static_cast<int>(plan_record->journal.size());
      runtime->measured_revision++;
      runtime->needs_reload = false;
    }  // else still needs_reload: the next request tries again
  }
  const absl::Status reloaded =
      plan.ok() ? absl::OkStatus()
                : absl::UnavailableError(absl::StrCat("job ", runtime->job_id,
                                                      " could not be re-read from the database after a failed write (",
                                                      plan.status().message(), "); nothing was changed; retry"));
  for (std::function<void(absl::Status)>& then : waiting) {
    executors_.completions->Post([then = std::move(then), reloaded]() mutable { then(reloaded); });
  }
  if (plan.ok()) NotifyListeners(*runtime);
}

}  // namespace surfmap
