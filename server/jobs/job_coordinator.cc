#include "server/jobs/job_coordinator.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <utility>

#include <nlohmann/json.hpp>
#include "absl/strings/str_cat.h"
#include "server/codec/fit_json.h"
#include "server/estimate/roughness.h"
#include "server/jobs/command_json.h"
#include "server/jobs/stored_plan.h"
#include "server/jobs/stored_trace.h"

namespace surfmap {
namespace {

constexpr int64_t kRetryAfterMs = 200;
// Objects are refined this far on upload to prove the mesh is usable.
constexpr int kUploadCheckLevel = 1;

SamplingPlanOptions PlanOptionsFor(const JobParams& p) {
  SamplingPlanOptions o;
  o.mode = p.mode;
  o.coarsest_level = p.coarsest_level;
  o.max_level = p.finest_level;
  o.threshold = p.threshold;
  o.distance.property = p.property;
  o.sample_budget = p.budget;
  o.max_retries = p.max_retries;
  o.probe = p.probe;
  o.seed = p.seed;
  return o;
}

// An answer to a command (trace or failure) must come from the rig holding
// its lease: checked before the plan is touched (the store checks again).
absl::Status CheckLeasedTo(const CommandRecord& command, const std::string& rig_id, const char* otherwise) {
  if (command.state != CommandState::kLeased) {
    return absl::FailedPreconditionError(absl::StrCat("command ", command.id, " is ",
                                                      std::string(CommandStateName(command.state)),
                                                      ", not leased: ", otherwise));
  }
  if (command.lease_owner != rig_id) {
    return absl::FailedPreconditionError(
        absl::StrCat("command ", command.id, " is leased to '", command.lease_owner, "', not to '", rig_id, "'"));
  }
  return absl::OkStatus();
}

NewFit NewFitOf(const TraceFit& fit, const FitOptions& options) {
  NewFit f;
  f.estimator_name = kEstimatorName;
  f.estimator_version = kEstimatorVersion;
  f.options_json = FitOptionsToJson(options).dump();
  f.result_json = TraceFitToJson(fit).dump();
  f.mu = fit.friction.mu;
  if (fit.roughness.a.size() > 0) f.a1 = fit.roughness.a[0];
  if (fit.roughness.a.size() > 1) f.a2 = fit.roughness.a[1];
  f.sigma = fit.roughness.sigma;
  return f;
}

std::vector<NewCommand> DrainCommands(SamplingPlan& plan) {
  std::vector<NewCommand> out;
  while (std::optional<ProbeCommand> c = plan.NextCommand()) {
    out.push_back(NewCommand{c->site.level, c->site.vertex, ProbeCommandToJson(*c)});
  }
  return out;
}

NewEvent Event(const std::string& kind, nlohmann::json detail) { return NewEvent{kind, detail.dump()}; }

// A leased command (or none: ask again after kRetryAfterMs) with its probe decoded.
absl::StatusOr<LeaseOutcome> LeaseOutcomeOf(std::optional<CommandRecord> leased) {
  LeaseOutcome outcome;
  if (!leased.has_value()) {
    outcome.retry_after_ms = kRetryAfterMs;
    return outcome;
  }
  absl::StatusOr<ProbeCommand> probe = ProbeCommandFromJson(leased->command_json);
  if (!probe.ok()) return probe.status();
  probe->attempt = leased->attempt;
  outcome.record = std::move(*leased);
  outcome.command = *probe;
  return outcome;
}

// The job's newest stored trace as a sample (null when it has none).
absl::StatusOr<std::shared_ptr<const AcceptedSample>> LoadLatestSample(Store& store,
                                                                       const std::optional<TraceRecord>& trace) {
  if (!trace.has_value()) return std::shared_ptr<const AcceptedSample>();
  auto sample = std::make_shared<AcceptedSample>();
  absl::StatusOr<CommandRecord> command = store.GetCommand(trace->command_id);
  if (!command.ok()) return command.status();
  absl::StatusOr<FitRecord> fit = store.GetFit(trace->id, 1);
  if (!fit.ok()) return fit.status();
  sample->command = std::move(*command);
  sample->trace_id = trace->id;
  sample->fit = std::move(*fit);
  sample->received_unix_ms = trace->received_unix_ms;
  return std::shared_ptr<const AcceptedSample>(std::move(sample));
}

}  // namespace

int64_t UnixMillisNow() {
  return std::chrono::duration_cast<std::chrono::milliseconds>(std::chrono::system_clock::now().time_since_epoch())
      .count();
}

JobCoordinator::JobCoordinator(Store* store, int64_t default_lease_ms)
    : store_(store), default_lease_ms_(default_lease_ms), surfaces_(store) {}

absl::Status JobCoordinator::LoadJobs() {
  absl::StatusOr<std::vector<JobRecord>> jobs = store_->ListJobs(0);
  if (!jobs.ok()) return jobs.status();
  for (const JobRecord& record : *jobs) {
    absl::StatusOr<std::shared_ptr<JobRuntime>> runtime = LoadRuntime(record);
    if (!runtime.ok()) {
      return absl::Status(runtime.status().code(),
                          absl::StrCat("job ", record.id, " cannot be restored: ", runtime.status().message()));
    }
    std::lock_guard<std::mutex> lock(mu_);
    jobs_[record.id] = *runtime;
  }
  return absl::OkStatus();
}

absl::StatusOr<std::shared_ptr<JobRuntime>> JobCoordinator::LoadRuntime(const JobRecord& record) {
  nlohmann::json params_json = nlohmann::json::parse(record.params_json, nullptr, false);
  if (params_json.is_discarded()) return absl::DataLossError("stored job parameters are not JSON");
  absl::StatusOr<JobParams> params = JobParamsFromJson(params_json);
  if (!params.ok()) return params.status();
  absl::StatusOr<std::shared_ptr<const LoopSurface>> surface = surfaces_.Get(params->object_id, params->finest_level);
  if (!surface.ok()) return surface.status();
  absl::StatusOr<PlanRecord> plan_record = store_->GetPlan(record.id);
  if (!plan_record.ok()) return plan_record.status();
  absl::StatusOr<SamplingPlan> plan = RestoreStoredPlan(*plan_record, PlanLevels(**surface));
  if (!plan.ok()) return plan.status();
  if (record.state == JobState::kCancelled) plan->Cancel();
  auto runtime = std::make_shared<JobRuntime>(record.id, *params, *surface, std::move(*plan));
  runtime->state = record.state;
  runtime->plan_revision = plan_record->revision;
  runtime->journal_entries = static_cast<int>(plan_record->journal.size());
  runtime->measured_revision = runtime->plan.Progress().measured;
  runtime->created_unix_ms = record.created_unix_ms;
  // The job row's time changes only with its state; traces and failures since
  // then are newer changes, each with an event written in its transaction.
  absl::StatusOr<JobActivity> activity = store_->GetJobActivity(record.id);
  if (!activity.ok()) return activity.status();
  runtime->updated_unix_ms = std::max(record.updated_unix_ms, activity->last_event_unix_ms.value_or(0));
  absl::StatusOr<std::shared_ptr<const AcceptedSample>> latest = LoadLatestSample(*store_, activity->latest_trace);
  if (!latest.ok()) return latest.status();
  runtime->latest_sample = std::move(*latest);
  return runtime;
}

absl::StatusOr<std::shared_ptr<JobRuntime>> JobCoordinator::Runtime(int64_t job_id) {
  {
    std::lock_guard<std::mutex> lock(mu_);
    auto it = jobs_.find(job_id);
    if (it != jobs_.end()) return it->second;
  }
  absl::StatusOr<JobRecord> record = store_->GetJob(job_id);
  if (!record.ok()) return record.status();
  absl::StatusOr<std::shared_ptr<JobRuntime>> runtime = LoadRuntime(*record);
  if (!runtime.ok()) return runtime.status();
  std::lock_guard<std::mutex> lock(mu_);
  auto [it, inserted] = jobs_.emplace(job_id, *runtime);
  return it->second;
}

absl::Status JobCoordinator::ReloadIfNeeded(JobRuntime& runtime) {
  if (!runtime.needs_reload) return absl::OkStatus();
  absl::StatusOr<JobRecord> record = store_->GetJob(runtime.job_id);
  if (!record.ok()) return record.status();
  absl::StatusOr<PlanRecord> plan_record = store_->GetPlan(runtime.job_id);
  if (!plan_record.ok()) return plan_record.status();
  absl::StatusOr<SamplingPlan> plan = RestoreStoredPlan(*plan_record, PlanLevels(*runtime.surface));
  if (!plan.ok()) return plan.status();
  runtime.plan = std::move(*plan);
  if (record->state == JobState::kCancelled) runtime.plan.Cancel();
  runtime.state = record->state;
  runtime.plan_revision = plan_record->revision;
  runtime.journal_entries = static_cast<int>(plan_record->journal.size());
  runtime.measured_revision++;
  runtime.needs_reload = false;
  return absl::OkStatus();
}

void JobCoordinator::MarkWriteFailed(const std::shared_ptr<JobRuntime>& runtime) { runtime->needs_reload = true; }

void JobCoordinator::Notify(const std::shared_ptr<JobRuntime>& runtime) {
  std::vector<std::function<void()>> listeners;
  {
    std::lock_guard<std::mutex> lock(runtime->mu);
    runtime->update_revision++;
    for (auto& [id, listener] : runtime->listeners) listeners.push_back(listener);
  }
  for (auto& listener : listeners) listener();
}

// ---------------------------------------------------------------- objects

absl::StatusOr<ObjectRecord> JobCoordinator::UploadObject(const std::string& name, MeshFormat format,
                                                          std::string bytes) {
  if (name.empty() || name.size() > 200) return absl::InvalidArgumentError("object name must have 1..200 characters");
  if (bytes.empty()) return absl::InvalidArgumentError("mesh is empty (0 bytes)");
  absl::StatusOr<ControlMesh> mesh = ParseControlMesh(bytes, format, name);
  if (!mesh.ok()) return mesh.status();
  absl::StatusOr<std::unique_ptr<LoopSurface>> check = LoopSurface::Create(*mesh, kUploadCheckLevel);
  if (!check.ok()) return check.status();
  NewObject object;
  object.name = name;
  object.mesh_format = format == MeshFormat::kPly ? "ply" : "obj";
  object.mesh_bytes = std::move(bytes);
  object.control_vertices = static_cast<int64_t>(mesh->positions.size());
  object.control_faces = static_cast<int64_t>(mesh->triangles.size());
  absl::StatusOr<int64_t> id = store_->CreateObject(object);
  if (!id.ok()) return id.status();
  return store_->GetObject(*id, /*include_mesh=*/false);
}

absl::StatusOr<std::shared_ptr<const LoopSurface>> JobCoordinator::Surface(int64_t object_id, int level) {
  if (level < 0 || level > 6) return absl::InvalidArgumentError(absl::StrCat("level must be in 0..6, got ", level));
  return surfaces_.Get(object_id, level);
}

// ---------------------------------------------------------------- jobs

JobSnapshot JobCoordinator::SnapshotLocked(JobRuntime& runtime, const JobRecord& record) {
  JobSnapshot s;
  s.record = record;
  s.record.state = runtime.state;
  s.params = runtime.params;
  s.record.updated_unix_ms = std::max(record.updated_unix_ms, runtime.updated_unix_ms);
  s.progress = runtime.plan.Progress();
  s.latest_sample = runtime.latest_sample;
  return s;
}

absl::StatusOr<LeasedCounts> JobCoordinator::LeasedCommands(int64_t job_id, const PlanProgress& progress) {
  absl::StatusOr<LeasedCounts> leased = store_->CountLeasedCommands(job_id, UnixMillisNow());
  if (!leased.ok()) return leased.status();
  LeasedCounts clamped;
  clamped.total = std::min(leased->total, progress.issued);
  for (const LevelProgress& level : progress.levels) {
    auto it = leased->by_level.find(level.level);
    if (it != leased->by_level.end()) clamped.by_level[level.level] = std::min(it->second, level.issued);
  }
  return clamped;
}

absl::Status JobCoordinator::AddLeasedCount(JobSnapshot& snapshot) {
  absl::StatusOr<LeasedCounts> leased = LeasedCommands(snapshot.record.id, snapshot.progress);
  if (!leased.ok()) return leased.status();
  snapshot.leased = std::move(*leased);
  return absl::OkStatus();
}

absl::StatusOr<JobSnapshot> JobCoordinator::CreateJob(const JobParams& params) {
  std::string why;
  if (!params.IsValid(&why)) return absl::InvalidArgumentError("job: " + why);
  absl::StatusOr<std::shared_ptr<const LoopSurface>> surface = surfaces_.Get(params.object_id, params.finest_level);
  if (!surface.ok()) return surface.status();
  absl::StatusOr<SamplingPlan> plan = SamplingPlan::Create(PlanLevels(**surface), PlanOptionsFor(params));
  if (!plan.ok()) return plan.status();

  NewJob job;
  job.object_id = params.object_id;
  job.params_json = JobParamsToJson(params).dump();
  job.commands = DrainCommands(*plan);
  job.plan_json = plan->SaveJson();
  job.events.push_back(Event("job_created", {{"initial_commands", job.commands.size()}}));
  absl::StatusOr<CreatedJob> created = store_->CreateJob(job);
  if (!created.ok()) return created.status();

  auto runtime = std::make_shared<JobRuntime>(created->job.id, params, *surface, std::move(*plan));
  runtime->created_unix_ms = created->job.created_unix_ms;
  runtime->updated_unix_ms = created->job.updated_unix_ms;
  {
    std::lock_guard<std::mutex> lock(mu_);
    jobs_[created->job.id] = runtime;
  }
  JobSnapshot snapshot;
  {
    std::lock_guard<std::mutex> lock(runtime->mu);
    snapshot = SnapshotLocked(*runtime, created->job);
  }
  snapshot.leased = LeasedCounts{};  // nothing can have been leased yet
  return snapshot;
}

absl::StatusOr<JobSnapshot> JobCoordinator::GetJob(int64_t job_id) {
  absl::StatusOr<JobRecord> record = store_->GetJob(job_id);
  if (!record.ok()) return record.status();
  absl::StatusOr<std::shared_ptr<JobRuntime>> runtime = Runtime(job_id);
  if (!runtime.ok()) return runtime.status();
  JobSnapshot snapshot;
  {
    std::lock_guard<std::mutex> lock((*runtime)->mu);
    if (absl::Status s = ReloadIfNeeded(**runtime); !s.ok()) return s;
    snapshot = SnapshotLocked(**runtime, *record);
  }
  if (absl::Status s = AddLeasedCount(snapshot); !s.ok()) return s;
  return snapshot;
}

absl::StatusOr<std::vector<JobSnapshot>> JobCoordinator::ListJobs(int64_t object_id) {
  absl::StatusOr<std::vector<JobRecord>> records = store_->ListJobs(object_id);
  if (!records.ok()) return records.status();
  std::vector<JobSnapshot> out;
  for (const JobRecord& record : *records) {
    absl::StatusOr<std::shared_ptr<JobRuntime>> runtime = Runtime(record.id);
    if (!runtime.ok()) return runtime.status();
    {
      std::lock_guard<std::mutex> lock((*runtime)->mu);
      out.push_back(SnapshotLocked(**runtime, record));
    }
    if (absl::Status s = AddLeasedCount(out.back()); !s.ok()) return s;
  }
  return out;
}

absl::StatusOr<JobSnapshot> JobCoordinator::SetJobState(int64_t job_id, JobState target) {
  absl::StatusOr<std::shared_ptr<JobRuntime>> runtime = Runtime(job_id);
  if (!runtime.ok()) return runtime.status();
  absl::StatusOr<JobRecord> record;
  {
    std::lock_guard<std::mutex> lock((*runtime)->mu);
    if (absl::Status s = ReloadIfNeeded(**runtime); !s.ok()) return s;
    JobState from = (*runtime)->state;
    if (!IsJobTransitionAllowed(from, target)) {
      return absl::FailedPreconditionError(absl::StrCat("job ", job_id, " is ", std::string(JobStateName(from)), "; cannot become ",
                                                        std::string(JobStateName(target))));
    }
    JobStateChange change{job_id, target, {Event("job_state", {{"from", std::string(JobStateName(from))}, {"to", std::string(JobStateName(target))}})}};
    record = store_->UpdateJobState(change);
    if (!record.ok()) return record.status();
    (*runtime)->state = target;
    (*runtime)->updated_unix_ms = std::max((*runtime)->updated_unix_ms, record->updated_unix_ms);
    if (target == JobState::kCancelled) (*runtime)->plan.Cancel();
  }
  Notify(*runtime);
  JobSnapshot snapshot;
  {
    std::lock_guard<std::mutex> lock((*runtime)->mu);
    snapshot = SnapshotLocked(**runtime, *record);
  }
  if (absl::Status s = AddLeasedCount(snapshot); !s.ok()) return s;
  return snapshot;
}

absl::StatusOr<std::vector<SiteRecord>> JobCoordinator::PlanSites(int64_t job_id, PlanProgress* progress) {
  absl::StatusOr<std::shared_ptr<JobRuntime>> runtime = Runtime(job_id);
  if (!runtime.ok()) return runtime.status();
  std::lock_guard<std::mutex> lock((*runtime)->mu);
  if (absl::Status s = ReloadIfNeeded(**runtime); !s.ok()) return s;
  *progress = (*runtime)->plan.Progress();
  return (*runtime)->plan.Sites();
}

absl::StatusOr<JobCoordinator::CommandContext> JobCoordinator::LoadCommandContext(int64_t command_id) {
  absl::StatusOr<CommandRecord> record = store_->GetCommand(command_id);
  if (!record.ok()) return record.status();
  absl::StatusOr<ProbeCommand> probe = ProbeCommandFromJson(record->command_json);
  if (!probe.ok()) return probe.status();
  absl::StatusOr<std::shared_ptr<JobRuntime>> runtime = Runtime(record->job_id);
  if (!runtime.ok()) return runtime.status();
  return CommandContext{std::move(*record), *probe, *runtime};
}

JobCoordinator::PlanWrite JobCoordinator::TakePlanChangeLocked(JobRuntime& runtime, const PlanJournalEntry& change) {
  PlanWrite write;
  write.new_commands = DrainCommands(runtime.plan);
  // Writes of one job are queued in order under its lock and committed in
  // queue order, so this write's base is the revision the previous one made.
  write.expected_revision = runtime.plan_revision++;
  const bool complete = runtime.plan.IsComplete();
  if (complete || runtime.journal_entries + 1 >= CheckpointInterval(runtime.plan)) {
    write.checkpoint_json = runtime.plan.SaveJson();
    runtime.journal_entries = 0;
  } else {
    write.journal_entry = PlanJournalEntryToJson(change);
    runtime.journal_entries++;
  }
  if (complete && runtime.state != JobState::kCompleted && runtime.state != JobState::kCancelled) {
    write.new_job_state = JobState::kCompleted;
    runtime.state = JobState::kCompleted;
  }
  return write;
}

// ---------------------------------------------------------------- probing

void JobCoordinator::LeaseCommand(const std::string& rig_id, int64_t job_id, LeaseCallback done) {
  if (rig_id.empty() || rig_id.size() > 100) {
    done(absl::InvalidArgumentError("rig_id must have 1..100 characters"));
    return;
  }
  std::shared_ptr<JobRuntime> runtime;
  if (job_id != 0) {
    absl::StatusOr<std::shared_ptr<JobRuntime>> found = Runtime(job_id);
    if (!found.ok()) {
      done(found.status());
      return;
    }
    runtime = *found;
    std::lock_guard<std::mutex> lock(runtime->mu);
    if (runtime->state == JobState::kCompleted || runtime->state == JobState::kCancelled) {
      LeaseOutcome finished;
      finished.job_finished = true;
      done(finished);
      return;
    }
  }
  LeaseRequest request;
  request.job_id = job_id;
  request.owner = rig_id;
  request.now_unix_ms = UnixMillisNow();
  request.lease_duration_ms = runtime ? runtime->params.lease_ms : default_lease_ms_;
  store_->LeaseNextCommandAsync(request, [done = std::move(done)](absl::StatusOr<std::optional<CommandRecord>> leased) {
    if (!leased.ok()) {
      done(leased.status());
      return;
    }
    done(LeaseOutcomeOf(std::move(*leased)));
  });
}

void JobCoordinator::SubmitTrace(int64_t command_id, const std::string& rig_id, DragTrace trace, bool lease_next,
                                 SubmitCallback done) {
  absl::StatusOr<CommandContext> context = LoadCommandContext(command_id);
  if (!context.ok()) {
    done(context.status());
    return;
  }
  const CommandRecord* command = &context->record;
  const ProbeCommand* probe = &context->probe;
  std::shared_ptr<JobRuntime> runtime = context->runtime;
  const FitOptions options = runtime->params.fit;
  // A done command goes straight to the store, which answers a retry with the
  // stored ids (already_accepted). Anything else must be leased by this rig:
  // checked here too, before the plan is touched.
  const bool retry = command->state == CommandState::kDone;
  if (!retry) {
    if (absl::Status held = CheckLeasedTo(*command, rig_id, "lease it before submitting a trace"); !held.ok()) {
      done(held);
      return;
    }
  }

  // The fit is pure computation: outside the job lock.
  absl::StatusOr<TraceFit> fit = FitTrace(trace, options);
  if (!fit.ok()) {
    done(absl::Status(fit.status().code(), absl::StrCat("trace for command ", command_id, ": ", fit.status().message())));
    return;
  }

  AcceptTraceRequest request;
  request.command_id = command_id;
  request.job_id = command->job_id;
  request.lease_owner = rig_id;
  request.samples = {};
  request.fit = NewFitOf(*fit, options);
  // The reply shows the stored fit as the store returns it from the write
  // (no read back: the callback runs on the store's writer thread, which
  // every rig waits for) with the fit already decoded here.
  auto decoded_fit = std::make_shared<const TraceFit>(*fit);
  if (lease_next) {
    request.lease_next = LeaseRequest{command->job_id, rig_id, UnixMillisNow(), runtime->params.lease_ms};
  }
  {
    std::lock_guard<std::mutex> lock(runtime->mu);
    if (absl::Status s = ReloadIfNeeded(*runtime); !s.ok()) {
      done(s);
      return;
    }
    if (runtime->state == JobState::kCancelled) {
      done(absl::FailedPreconditionError(absl::StrCat("job ", runtime->job_id, " is cancelled; trace for command ",
                                                      command_id, " not accepted")));
      return;
    }
    PlanJournalEntry answer;
    answer.sequence = probe->sequence;
    answer.fit = TextureOf(*fit);
    absl::Status recorded =
        retry ? absl::NotFoundError("already answered") : ApplyPlanJournalEntry(answer, runtime->plan);
    if (recorded.ok()) {
      TakePlanChangeLocked(*runtime, answer).MoveInto(request);
      runtime->measured_revision++;
      request.events.push_back(Event("trace_accepted", {{"command_id", command_id},
                                                       {"vertex", probe->site.vertex},
                                                       {"level", probe->site.level},
                                                       {"mu", fit->friction.mu},
                                                       {"rig", rig_id}}));
    } else if (recorded.code() != absl::StatusCode::kNotFound) {
      done(recorded);
      return;
    }
    // NOT_FOUND: the plan has this command's answer already (a retry, possibly
    // still being written): the store answers already_accepted without writing.
    request.samples = ToStoredSamples(trace);
    const bool plan_changed = recorded.ok();
    store_->AcceptTraceAsync(
        std::move(request),
        [this, runtime, plan_changed, lease_next, decoded_fit, command = context->record,
         probe = context->probe, done = std::move(done)](
            absl::StatusOr<AcceptTraceResult> result) {
          if (!result.ok()) {
            if (plan_changed) MarkWriteFailed(runtime);
            done(result.status());
            return;
          }
          SubmitOutcome outcome;
          outcome.command = command;
          outcome.probe = probe;
          outcome.trace_id = result->trace_id;
          outcome.already_accepted = result->already_accepted;
          if (result->already_accepted) {
            // A retry: its reply shows the fit stored the first time. The
            // trace is durable either way; a failed read is reported (the rig
            // retries, idempotently) rather than answered with an empty fit.
            absl::StatusOr<FitRecord> stored = store_->GetFit(result->trace_id, 1);
            if (!stored.ok()) {
              done(stored.status());
              return;
            }
            outcome.fit = std::move(*stored);
          } else if (result->fit.has_value()) {
            outcome.fit = std::move(*result->fit);
            outcome.decoded_fit = decoded_fit;
          } else {
            done(absl::InternalError(absl::StrCat("trace ", result->trace_id, " was stored without its fit")));
            return;
          }
          std::shared_ptr<const AcceptedSample> accepted;
          if (plan_changed && !result->already_accepted) {
            auto sample = std::make_shared<AcceptedSample>();
            sample->command = command;
            sample->trace_id = result->trace_id;
            sample->fit = outcome.fit;
            // The trace and its fit are stored in one transaction at one time.
            sample->received_unix_ms = result->accepted_unix_ms;
            accepted = std::move(sample);
          }
          {
            std::lock_guard<std::mutex> lock(runtime->mu);
            outcome.progress = runtime->plan.Progress();
            // Writes of one job commit in queue order, so a later trace never
            // lands here before an earlier one; the id check is a safeguard.
            if (accepted && (!runtime->latest_sample || runtime->latest_sample->trace_id < accepted->trace_id)) {
              runtime->updated_unix_ms = std::max(runtime->updated_unix_ms, accepted->received_unix_ms);
              runtime->latest_sample = std::move(accepted);
            }
          }
          if (lease_next) {
            absl::StatusOr<LeaseOutcome> next = LeaseOutcomeOf(std::move(result->next_command));
            if (!next.ok()) {
              done(next.status());
              return;
            }
            if (!next->record) {
              std::lock_guard<std::mutex> lock(runtime->mu);
              next->job_finished = runtime->state == JobState::kCompleted || runtime->state == JobState::kCancelled;
            }
            outcome.next = std::move(*next);
          }
          if (plan_changed) Notify(runtime);
          done(std::move(outcome));
        });
  }
}

void JobCoordinator::ReportFailure(int64_t command_id, const std::string& rig_id, const std::string& reason,
                                   FailureCallback done) {
  if (reason.empty() || reason.size() > 1000) {
    done(absl::InvalidArgumentError("failure reason must have 1..1000 characters"));
    return;
  }
  absl::StatusOr<CommandContext> context = LoadCommandContext(command_id);
  if (!context.ok()) {
    done(context.status());
    return;
  }
  const CommandRecord* command = &context->record;
  const ProbeCommand* probe = &context->probe;
  if (absl::Status held = CheckLeasedTo(*command, rig_id, "nothing to report"); !held.ok()) {
    done(held);
    return;
  }
  std::shared_ptr<JobRuntime> runtime = context->runtime;
  std::lock_guard<std::mutex> lock(runtime->mu);
  if (absl::Status s = ReloadIfNeeded(*runtime); !s.ok()) {
    done(s);
    return;
  }
  PlanJournalEntry answer;
  answer.kind = PlanJournalEntry::Kind::kFailure;
  answer.sequence = probe->sequence;
  answer.reason = reason;
  absl::Status recorded = ApplyPlanJournalEntry(answer, runtime->plan);
  if (!recorded.ok()) {
    done(recorded);
    return;
  }
  // Read before TakePlanChangeLocked: it re-issues a re-queued site at once
  // (pending -> issued), so afterwards a retry no longer looks pending.
  const SiteRecord* site = runtime->plan.FindSite(probe->site.vertex);
  const bool will_retry = site != nullptr && site->state == SiteState::kPending;
  FailCommandRequest request;
  request.command_id = command_id;
  request.job_id = command->job_id;
  request.lease_owner = rig_id;
  request.reason = reason;
  TakePlanChangeLocked(*runtime, answer).MoveInto(request);
  request.events.push_back(Event("probe_failed", {{"command_id", command_id}, {"reason", reason}, {"rig", rig_id},
                                                  {"will_retry", will_retry}}));
  store_->FailCommandAsync(std::move(request), [this, runtime, will_retry, done = std::move(done)](
                                                   absl::StatusOr<FailCommandResult> result) {
    if (!result.ok()) {
      MarkWriteFailed(runtime);
      done(result.status());
      return;
    }
    {
      std::lock_guard<std::mutex> lock(runtime->mu);
      runtime->updated_unix_ms = std::max(runtime->updated_unix_ms, UnixMillisNow());
    }
    Notify(runtime);
    done(will_retry);
  });
}

// ---------------------------------------------------------------- map

absl::StatusOr<MapSnapshot> JobCoordinator::Map(int64_t job_id) {
  absl::StatusOr<std::shared_ptr<JobRuntime>> found = Runtime(job_id);
  if (!found.ok()) return found.status();
  std::shared_ptr<JobRuntime> runtime = *found;
  std::lock_guard<std::mutex> map_lock(runtime->map_mu);
  int64_t revision;
  std::vector<MapSample> samples;
  {
    std::lock_guard<std::mutex> lock(runtime->mu);
    if (absl::Status s = ReloadIfNeeded(*runtime); !s.ok()) return s;
    revision = runtime->measured_revision;
    if (runtime->map_snapshot.surface && runtime->map_snapshot.measured_revision == revision) {
      return runtime->map_snapshot;
    }
    samples = runtime->plan.MeasuredSamples();
  }
  if (!runtime->map_builder) {
    absl::StatusOr<FrictionMap> builder = FrictionMap::Create(runtime->surface->finest());
    if (!builder.ok()) return builder.status();
    runtime->map_builder.emplace(std::move(*builder));
  }
  MapSnapshot snapshot;
  snapshot.surface = runtime->surface;
  snapshot.measured_revision = revision;
  if (!samples.empty()) {
    if (absl::Status s = runtime->map_builder->SetSamples(std::move(samples)); !s.ok()) return s;
    snapshot.map = std::make_shared<const FrictionMap>(*runtime->map_builder);
  }
  runtime->map_snapshot = snapshot;
  return snapshot;
}

absl::StatusOr<RefitOutcome> JobCoordinator::RefitJob(int64_t job_id, const FitOptions& options) {
  std::string why;
  if (!options.IsValid(&why)) return absl::InvalidArgumentError("estimator settings: " + why);
  absl::StatusOr<std::vector<TraceRecord>> traces = store_->ListTraces(job_id, /*include_samples=*/true);
  if (!traces.ok()) return traces.status();
  if (traces->empty()) return absl::FailedPreconditionError(absl::StrCat("job ", job_id, " has no traces to refit"));
  RefitOutcome outcome;
  std::vector<TraceRefit> refits;
  for (const TraceRecord& trace : *traces) {
    absl::StatusOr<TraceFit> fit = FitTrace(FromStoredSamples(trace.samples), options);
    if (!fit.ok()) {
      ++outcome.failed;
      continue;
    }
    refits.push_back(TraceRefit{trace.id, NewFitOf(*fit, options)});
  }
  if (refits.empty()) return absl::FailedPreconditionError("no trace of the job could be refitted with these settings");
  absl::StatusOr<std::vector<FitRecord>> stored = store_->AddFits(refits);
  if (!stored.ok()) return stored.status();
  outcome.refitted = static_cast<int>(stored->size());
  outcome.version = stored->front().version;
  return outcome;
}

// ---------------------------------------------------------------- watchers

absl::StatusOr<int64_t> JobCoordinator::Watch(int64_t job_id, std::function<void()> listener) {
  absl::StatusOr<std::shared_ptr<JobRuntime>> runtime = Runtime(job_id);
  if (!runtime.ok()) return runtime.status();
  std::lock_guard<std::mutex> lock((*runtime)->mu);
  int64_t id = (*runtime)->next_listener_id++;
  (*runtime)->listeners[id] = std::move(listener);
  return id;
}

void JobCoordinator::Unwatch(int64_t job_id, int64_t handle) {
  absl::StatusOr<std::shared_ptr<JobRuntime>> runtime = Runtime(job_id);
  if (!runtime.ok()) return;
  std::lock_guard<std::mutex> lock((*runtime)->mu);
  (*runtime)->listeners.erase(handle);
}

absl::StatusOr<int64_t> JobCoordinator::UpdateRevision(int64_t job_id) {
  absl::StatusOr<std::shared_ptr<JobRuntime>> runtime = Runtime(job_id);
  if (!runtime.ok()) return runtime.status();
  std::lock_guard<std::mutex> lock((*runtime)->mu);
  return (*runtime)->update_revision;
}

}  // namespace surfmap
