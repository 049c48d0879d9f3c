#include "server/jobs/probe_protocol.h"

#include <algorithm>
#include <optional>
#include <utility>

#include <nlohmann/json.hpp>
#include <spdlog/spdlog.h>
#include "absl/strings/str_cat.h"
#include "server/base/status_macros.h"
#include "server/base/utf8_text.h"
#include "server/jobs/command_json.h"
#include "server/jobs/job_watchers.h"
#include "server/jobs/plan_write.h"
#include "server/estimate/line_sample.h"
#include "server/jobs/stored_plan.h"
#include "server/jobs/stored_trace.h"
#include "server/jobs/trace_frame_check.h"
#include "server/jobs/trace_plausibility.h"
#include "server/plan/plan_journal.h"

namespace surfmap {
namespace {

// One info line when a job completes (durably): what an operator watching
// the log wants to know without opening a dashboard.
void LogJobCompleted(int64_t job_id, const PlanProgress& progress) {
  spdlog::info("job completed job_id={} measured={} failed={} skipped={}", job_id, progress.measured,
               progress.failed, progress.skipped);
}

absl::Status ValidateRigId(const std::string& rig_id) {
  return ValidateName("rig_id", rig_id, 1, 100);  // characters, valid UTF-8, one line
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
    return absl::FailedPreconditionError(absl::StrCat(
        "command ", command.id, " is leased to '", command.lease_owner, "' (attempt ", command.attempt,
        "), not to '", rig_id, "': the lease of '", rig_id,
        "' expired and the command was leased again; nothing from '", rig_id, "' was stored"));
  }
  return absl::OkStatus();
}

}  // namespace

ProbeProtocol::ProbeProtocol(Store* store, JobRegistry* registry, RigRegistrations* rigs, JobExecutors executors,
                             int64_t default_lease_ms)
    : store_(store), registry_(registry), rigs_(rigs), executors_(executors), default_lease_ms_(default_lease_ms) {}

// ---------------------------------------------------------------- frames

namespace {

// The commanded drag's contact path on the surface: centred on the site when
// the surface allows (as the simulated rig drags), else from the site on.
void CommandContactPath(const LoopSurface& surface, const ProbeCommand& command, std::vector<Eigen::Vector3d>* points,
                        std::vector<Eigen::Vector3d>* normals) {
  constexpr double kStepMm = 1.0;
  const double length = command.probe.segment_length_mm;
  Eigen::Vector3d start = command.position, direction = command.drag_direction;
  absl::StatusOr<SurfacePath> back = surface.TraceDragPath(command.position, -command.drag_direction, 0.5 * length,
                                                           kStepMm);
  if (back.ok() && back->points.size() >= 2) {
    start = back->points.back();
    direction = back->points[back->points.size() - 2] - back->points.back();
  }
  absl::StatusOr<SurfacePath> path = surface.TraceDragPath(start, direction, length, kStepMm);
  if (!path.ok()) path = surface.TraceDragPath(command.position, command.drag_direction, length, kStepMm);
  if (!path.ok()) return;  // no room on the surface: the site alone
  *points = std::move(path->points);
  *normals = std::move(path->normals);
}

}  // namespace

std::optional<ProbeProtocol::RigFrameSource> ProbeProtocol::RigFrameSourceOf(const LeaseOutcome& outcome,
                                                                             const std::string& rig_id) const {
  if (!outcome.command || !outcome.record || rigs_ == nullptr) return std::nullopt;
  std::shared_ptr<JobRuntime> runtime = registry_->Find(outcome.record->job_id);
  if (!runtime) return std::nullopt;
  std::shared_ptr<const RegisteredRig> rig = rigs_->Latest(runtime->object_id, rig_id);
  if (!rig) return std::nullopt;
  return RigFrameSource{runtime->surface, std::move(rig)};
}

void ProbeProtocol::AttachRigFrame(LeaseOutcome& outcome, const RigFrameSource& source) {
  const ProbeCommand& c = *outcome.command;
  std::vector<Eigen::Vector3d> points, normals;
  if (source.surface) CommandContactPath(*source.surface, c, &points, &normals);
  outcome.rig_frame =
      CommandInRigFrame(source.rig->registration, c.position, c.normal, c.drag_direction, points, normals);
  outcome.rig_registration = source.rig;
}

absl::StatusOr<std::shared_ptr<const RegisteredRig>> ProbeProtocol::TraceRegistration(
    const CommandContext& context, const std::string& rig_id, TraceFrameChoice frame) const {
  const int64_t object_id = context.runtime->object_id;
  if (frame.registration_id != 0) {
    if (frame.frame == TraceFrame::kObject) {
      return absl::InvalidArgumentError("registration_id is set but the trace is stated in the object's frame "
                                        "(TRACE_FRAME_OBJECT): a registration is only read for a rig frame");
    }
    if (rigs_ == nullptr) return absl::FailedPreconditionError("this server keeps no rig registrations");
    absl::StatusOr<std::shared_ptr<const RegisteredRig>> rig = rigs_->Get(frame.registration_id);
    if (!rig.ok()) return rig.status();
    const RigRegistrationRecord& record = (*rig)->record;
    if (record.object_id != object_id || record.rig_name != rig_id) {
      return absl::InvalidArgumentError(absl::StrCat(
          "registration ", frame.registration_id, " is rig '", record.rig_name, "' on object ", record.object_id,
          ", not rig '", rig_id, "' on object ", object_id, " (the command's job's object)"));
    }
    return *std::move(rig);
  }
  std::shared_ptr<const RegisteredRig> latest = rigs_ ? rigs_->Latest(object_id, rig_id) : nullptr;
  if (!latest && frame.frame != TraceFrame::kObject) {
    return absl::FailedPreconditionError(absl::StrCat(
        "trace for command ", context.record.id, " is stated in ", std::string(TraceFrameName(frame.frame)),
        " frame, but rig '", rig_id, "' has no registration for object ", object_id,
        ": register the rig (SetRigRegistration) or send the trace in the object's frame"));
  }
  return latest;
}

// ---------------------------------------------------------------- leasing

void ProbeProtocol::LeaseCommand(const std::string& rig_id, int64_t job_id, LeaseCallback done) {
  if (absl::Status s = ValidateRigId(rig_id); !s.ok()) return done(s);
  if (job_id < 0) return done(absl::InvalidArgumentError("job_id must be >= 0 (0 = any)"));
  int64_t lease_ms = default_lease_ms_;
  if (job_id != 0) {
    bool finished = false;
    if (std::shared_ptr<JobRuntime> runtime = registry_->Find(job_id)) {
      MutexLock lock(&runtime->mu);
      finished = IsFinalJobState(runtime->state);
      lease_ms = runtime->params.lease_ms;
    } else {
      // Not in memory: only a finished job (one small read says so).
      absl::StatusOr<JobRecord> record = store_->GetJob(job_id);
      if (!record.ok()) return done(record.status());
      finished = IsFinalJobState(record->state);
    }
    if (finished) {
      LeaseOutcome outcome;
      outcome.job_finished = true;
      return done(outcome);
    }
  }
  registry_->lookahead().RigAsked(rig_id, UnixMillisNow(), lease_ms);
  LeaseRequest request{job_id, rig_id, UnixMillisNow(), lease_ms};
  store_->LeaseNextCommandAsync(request, [this, rig_id, done = std::move(done)](
                                             absl::StatusOr<std::optional<CommandRecord>> leased) mutable {
    executors_.completions->Post([this, rig_id, leased = std::move(leased), done = std::move(done)]() mutable {
      if (!leased.ok()) return done(leased.status());
      absl::StatusOr<LeaseOutcome> outcome = LeaseOutcomeOf(std::move(*leased));
      if (!outcome.ok()) return done(outcome.status());
      std::optional<RigFrameSource> source = RigFrameSourceOf(*outcome, rig_id);
      if (!source) return done(std::move(outcome));
      // Tracing the surface path is off the completions thread (see AttachRigFrame).
      executors_.probes->Post([outcome = std::move(*outcome), source = std::move(*source),
                               done = std::move(done)]() mutable {
        AttachRigFrame(outcome, source);
        done(std::move(outcome));
      });
    });
  });
}

// ---------------------------------------------------------------- traces

absl::StatusOr<ProbeProtocol::CommandContext> ProbeProtocol::LoadCommandContext(int64_t command_id) {
  if (command_id <= 0) return absl::InvalidArgumentError("command_id must be a positive command id");
  SURFMAP_ASSIGN_OR_RETURN(CommandRecord record, store_->GetCommand(command_id));
  absl::StatusOr<ProbeCommand> probe = ProbeCommandFromJson(record.command_json);
  if (!probe.ok()) {
    return absl::DataLossError(absl::StrCat("stored command ", command_id, " cannot be read: ", probe.status().message()));
  }
  SURFMAP_ASSIGN_OR_RETURN(std::shared_ptr<JobRuntime> runtime, registry_->Get(record.job_id));
  return CommandContext{std::move(record), std::move(*probe), std::move(runtime)};
}

void ProbeProtocol::SubmitTrace(int64_t command_id, const std::string& rig_id, TraceSource source, bool lease_next,
                                TraceFrameChoice frame, SubmitCallback done, std::string metadata_json) {
  if (absl::Status s = ValidateRigId(rig_id); !s.ok()) return done(s);
  if (command_id <= 0) return done(absl::InvalidArgumentError("command_id must be a positive command id"));
  auto shared_done = std::make_shared<SubmitCallback>(std::move(done));
  const bool queued = executors_.probes->Submit([this, command_id, rig_id, source = std::move(source), lease_next,
                                               frame, metadata_json = std::move(metadata_json), shared_done] {
    FitAndSubmit(command_id, rig_id, source, lease_next, frame, metadata_json, std::move(*shared_done));
  });
  if (!queued) (*shared_done)(absl::UnavailableError("server busy: work queue full, retry the trace later"));
}

void ProbeProtocol::FitAndSubmit(int64_t command_id, const std::string& rig_id, const TraceSource& source,
                                 bool lease_next, TraceFrameChoice frame, const std::string& metadata_json,
                                 SubmitCallback done) {
  absl::StatusOr<DragTrace> made = source();
  if (!made.ok()) return done(made.status());
  const DragTrace as_sent = std::move(*made);  // stored exactly like this
  absl::StatusOr<CommandContext> context = LoadCommandContext(command_id);
  if (!context.ok()) return done(context.status());
  // A done command: this is a repeated submission; the store tells a retry
  // (same rig, same samples) from a conflict. No fit, no plan change.
  const bool repeated = context->record.state == CommandState::kDone;
  TraceFit fit;
  TraceFrameRecord stored_frame;
  if (!repeated) {
    if (absl::Status held = CheckLeasedTo(context->record, rig_id, "lease it before submitting a trace"); !held.ok()) {
      return done(held);
    }
    absl::StatusOr<std::shared_ptr<const RegisteredRig>> rig = TraceRegistration(*context, rig_id, frame);
    if (!rig.ok()) return done(rig.status());
    // The checks and the fit read the object's frame (a copy only when converted).
    std::optional<DragTrace> converted;
    if (frame.frame != TraceFrame::kObject) converted = TraceToObjectFrame(as_sent, frame.frame, (*rig)->registration);
    const DragTrace& trace = converted ? *converted : as_sent;
    if (frame.frame != TraceFrame::kObject) {
      stored_frame.frame = std::string(TraceFrameName(frame.frame));
      stored_frame.registration_id = (*rig)->record.id;
    }
    // Plausibility first: one cheap pass, before any work that grows with
    // what the trace claims (a fit's grids follow its path length).
    const TraceLimits& limits = context->runtime->params.limits;
    if (absl::Status plausible = CheckTraceAgainstCommand(trace, context->probe, limits); !plausible.ok()) {
      if (PlausibilityCheckName(plausible).empty()) {  // malformed: nothing worth keeping
        return done(absl::Status(plausible.code(), absl::StrCat("trace for command ", command_id, ": ",
                                                                plausible.message())));
      }
      return KeepRejected(*context, rig_id, as_sent, stored_frame,
                          ExplainWrongFrame(plausible, as_sent, frame.frame, rig->get(), context->probe, limits),
                          std::move(done));
    }
    // The fit is pure computation: on this pool thread, outside any lock.
    absl::StatusOr<TraceFit> fitted = FitTrace(trace, context->runtime->params.fit);
    if (!fitted.ok()) {
      return done(absl::Status(fitted.status().code(),
                               absl::StrCat("trace for command ", command_id, ": ", fitted.status().message())));
    }
    if (absl::Status plausible = CheckFitAgainstCommand(trace, *fitted, context->probe, limits); !plausible.ok()) {
      return KeepRejected(*context, rig_id, as_sent, stored_frame,
                          ExplainWrongFrame(plausible, as_sent, frame.frame, rig->get(), context->probe, limits),
                          std::move(done));
    }
    fit = std::move(*fitted);
  }
  absl::Status refused = QueueTrace(*context, rig_id, repeated ? TraceFit{} : fit, ToStoredSamples(as_sent),
                                    lease_next, stored_frame, metadata_json, done);
  if (!refused.ok()) done(refused);  // after the job's lock is released
}

void ProbeProtocol::KeepRejected(const CommandContext& context, const std::string& rig_id, const DragTrace& trace,
                                 const TraceFrameRecord& frame, const absl::Status& refusal, SubmitCallback done) {
  NewRejectedTrace rejected;
  rejected.command_id = context.record.id;
  rejected.job_id = context.record.job_id;
  rejected.rig_id = rig_id;
  rejected.check_name = PlausibilityCheckName(refusal);
  rejected.message = std::string(refusal.message());
  rejected.encoded_samples = EncodeSamples(ToStoredSamples(trace));
  rejected.frame = frame.frame;  // the samples are kept as sent: in this frame
  rejected.registration_id = frame.registration_id;
  rejected.events.push_back(Event("trace_rejected", {{"command_id", context.record.id},
                                                     {"rig", rig_id},
                                                     {"check", rejected.check_name},
                                                     {"message", rejected.message},
                                                     {"frame", frame.frame},
                                                     {"registration_id", frame.registration_id}}));
  const absl::Status answer(refusal.code(),
                            absl::StrCat("trace for command ", context.record.id, " refused (kept for inspection, "
                                         "not in the map): ", refusal.message()));
  std::shared_ptr<JobRuntime> runtime = context.runtime;
  store_->RecordRejectedTraceAsync(std::move(rejected), [this, runtime, answer, done = std::move(done)](
                                                           absl::StatusOr<int64_t> kept) mutable {
    executors_.completions->Post([runtime, answer, kept, done = std::move(done)]() mutable {
      // The refusal stands whether or not keeping the trace worked.
      NotifyListeners(*runtime);
      done(kept.ok() ? answer : absl::Status(answer.code(), absl::StrCat(answer.message(), " (keeping it failed: ",
                                                                          kept.status().message(), ")")));
    });
  });
}

absl::Status ProbeProtocol::QueueTrace(const CommandContext& context, const std::string& rig_id, const TraceFit& fit,
                                       std::vector<StoredSample> samples, bool lease_next,
                                       const TraceFrameRecord& frame, const std::string& metadata_json,
                                       SubmitCallback& done) {
  JobRuntime& runtime = *context.runtime;
  const bool repeated = context.record.state == CommandState::kDone;
  AcceptTraceRequest request;
  request.command_id = context.record.id;
  request.job_id = context.record.job_id;
  request.lease_owner = rig_id;
  request.encoded_samples = EncodeSamples(samples);  // O(samples): before the lock
  request.metadata_json = metadata_json;
  request.frame = frame.frame;
  request.registration_id = frame.registration_id;
  if (lease_next) {
    request.lease_next = LeaseRequest{context.record.job_id, rig_id, UnixMillisNow(), runtime.params.lease_ms};
  }
  TraceWrite pending{context, /*plan_changed=*/false, /*completes_job=*/false, lease_next, nullptr, rig_id};
  registry_->lookahead().RigAsked(rig_id, UnixMillisNow(), runtime.params.lease_ms);
  const int keep_issued = registry_->lookahead().CommandsAhead(UnixMillisNow());
  MutexLock lock(&runtime.mu);
  if (!repeated) {
    SURFMAP_RETURN_IF_ERROR(registry_->CheckTakesAnswersLocked(runtime, "traces"));
    PlanJournalEntry answer;
    answer.sequence = context.probe.sequence;
    answer.fit = TextureOf(fit);
    answer.line = LineSampleOf(fit);  // the plan and the map use the whole drag
    absl::Status recorded = ApplyPlanJournalEntry(answer, runtime.plan);
    if (recorded.code() == absl::StatusCode::kNotFound) {
      // The plan has this command's answer already: the same trace is being
      // written right now. Its outcome decides; ask the rig to come back.
      return absl::UnavailableError(absl::StrCat("a trace for command ", context.record.id,
                                                 " is being stored; retry to learn its outcome"));
    }
    SURFMAP_RETURN_IF_ERROR(recorded);
    PlanWrite write = TakePlanChangeLocked(runtime, answer, keep_issued);
    pending.completes_job = write.new_job_state.has_value();
    std::move(write).MoveInto(request);
    runtime.measured_revision++;
    pending.plan_changed = true;
    request.fit = NewFitOf(fit, runtime.params.fit);
    request.events.push_back(Event("trace_accepted", {{"command_id", context.record.id},
                                                      {"vertex", context.probe.site.vertex},
                                                      {"level", context.probe.site.level},
                                                      {"mu", fit.friction.mu},
                                                      {"rig", rig_id}}));
    pending.decoded_fit = std::make_shared<const TraceFit>(fit);
  }
  store_->AcceptTraceAsync(std::move(request), [this, pending = std::move(pending), done = std::move(done)](
                                                   absl::StatusOr<AcceptTraceResult> result) mutable {
    executors_.completions->Post(
        [this, pending = std::move(pending), result = std::move(result), done = std::move(done)]() mutable {
          ApplyAcceptedTrace(pending, std::move(result), std::move(done));
        });
  });
  return absl::OkStatus();
}

void ProbeProtocol::ApplyAcceptedTrace(const TraceWrite& pending, absl::StatusOr<AcceptTraceResult> result,
                                       SubmitCallback done) {
  const CommandContext& context = pending.context;
  JobRuntime& runtime = *context.runtime;
  if (!result.ok()) {
    if (!pending.plan_changed) return done(result.status());
    return done(registry_->MarkWriteFailed(runtime, result.status()));
  }
  if (!result->fit.has_value()) {
    return done(absl::DataLossError(absl::StrCat("trace ", result->trace_id, " was stored without its fit")));
  }
  SubmitOutcome outcome;
  outcome.command = context.record;
  outcome.command.state = CommandState::kDone;
  outcome.command.lease_owner = context.record.lease_owner;
  outcome.probe = context.probe;
  outcome.trace_id = result->trace_id;
  outcome.fit = std::move(*result->fit);
  outcome.received_unix_ms = result->accepted_unix_ms;
  outcome.metadata_json = std::move(result->metadata_json);
  outcome.already_accepted = result->already_accepted;
  if (!result->already_accepted) outcome.decoded_fit = pending.decoded_fit;
  bool finished = false;
  bool completed_now = false;
  {
    MutexLock lock(&runtime.mu);
    outcome.progress = runtime.plan.Progress();
    if (pending.plan_changed && !result->already_accepted) {
      // Completions run in commit order: this is the newest trace.
      runtime.latest_sample = std::make_shared<AcceptedSample>(static_cast<const AcceptedSample&>(outcome));
      runtime.updated_unix_ms = std::max(runtime.updated_unix_ms, outcome.received_unix_ms);
      if (pending.completes_job) {
        runtime.durable_state = JobState::kCompleted;  // written with this trace
        completed_now = true;
      }
    }
    finished = IsFinalJobState(runtime.durable_state);
  }
  std::optional<RigFrameSource> next_frame;
  if (pending.lease_next) {
    absl::StatusOr<LeaseOutcome> next = LeaseOutcomeOf(std::move(result->next_command));
    if (!next.ok()) return done(next.status());
    if (!next->record) next->job_finished = finished;
    next_frame = RigFrameSourceOf(*next, pending.rig_id);
    outcome.next = std::move(*next);
  }
  if (finished) registry_->NoteFinished(runtime.job_id);
  if (completed_now) LogJobCompleted(runtime.job_id, outcome.progress);
  if (pending.plan_changed) NotifyListeners(runtime);
  if (!next_frame) return done(std::move(outcome));
  // The memory is up to date (above, in commit order); only the answer waits
  // for the next command's rig frame, traced off the completions thread.
  executors_.probes->Post([outcome = std::move(outcome), source = std::move(*next_frame),
                           done = std::move(done)]() mutable {
    AttachRigFrame(*outcome.next, source);
    done(std::move(outcome));
  });
}

// ---------------------------------------------------------------- failures

void ProbeProtocol::ReportFailure(int64_t command_id, const std::string& rig_id, const std::string& reason,
                                  FailureKind kind, FailureCallback done) {
  if (absl::Status s = ValidateRigId(rig_id); !s.ok()) return done(s);
  // A driver's own words may span lines (they are escaped in the log), but
  // must be UTF-8 and are counted in characters.
  if (std::optional<size_t> chars = Utf8Length(reason); !chars || *chars < 1 || *chars > 1000) {
    return done(absl::InvalidArgumentError(
        chars ? absl::StrCat("failure reason must have 1..1000 characters, got ", *chars)
              : std::string("failure reason is not valid UTF-8")));
  }
  auto shared_done = std::make_shared<FailureCallback>(std::move(done));
  const bool queued = executors_.probes->Submit([this, command_id, rig_id, reason, kind, shared_done] {
    FailureCallback done = std::move(*shared_done);
    absl::StatusOr<CommandContext> context = LoadCommandContext(command_id);
    if (!context.ok()) return done(context.status());
    if (absl::Status held = CheckLeasedTo(context->record, rig_id, "nothing to report"); !held.ok()) {
      return done(held);
    }
    absl::Status refused = QueueFailure(*context, rig_id, reason, kind, done);
    if (!refused.ok()) done(refused);
  });
  if (!queued) (*shared_done)(absl::UnavailableError("server busy: work queue full, retry the report later"));
}

absl::Status ProbeProtocol::QueueFailure(const CommandContext& context, const std::string& rig_id,
                                         const std::string& reason, FailureKind kind, FailureCallback& done) {
  JobRuntime& runtime = *context.runtime;
  registry_->lookahead().RigAsked(rig_id, UnixMillisNow(), runtime.params.lease_ms);
  const int keep_issued = registry_->lookahead().CommandsAhead(UnixMillisNow());
  MutexLock lock(&runtime.mu);
  SURFMAP_RETURN_IF_ERROR(registry_->CheckTakesAnswersLocked(runtime, "failure reports"));
  PlanJournalEntry answer;
  answer.kind = PlanJournalEntry::Kind::kFailure;
  answer.sequence = context.probe.sequence;
  answer.reason = reason;
  answer.failure = kind;
  SURFMAP_RETURN_IF_ERROR(ApplyPlanJournalEntry(answer, runtime.plan));
  // Read before TakePlanChangeLocked: it re-issues a re-queued site at once
  // (pending -> issued), so afterwards a retry no longer looks pending.
  const SiteRecord* site = runtime.plan.FindSite(context.probe.site.vertex);
  const bool will_retry = site != nullptr && site->state == SiteState::kPending;
  FailCommandRequest request;
  request.command_id = context.record.id;
  request.job_id = context.record.job_id;
  request.lease_owner = rig_id;
  request.reason = reason;
  PlanWrite write = TakePlanChangeLocked(runtime, answer, keep_issued);
  const bool completes_job = write.new_job_state.has_value();
  std::move(write).MoveInto(request);
  request.events.push_back(Event("probe_failed", {{"command_id", context.record.id},
                                                  {"reason", reason},
                                                  {"kind", std::string(FailureKindName(kind))},
                                                  {"rig", rig_id},
                                                  {"will_retry", will_retry}}));
  std::shared_ptr<JobRuntime> runtime_ptr = context.runtime;
  store_->FailCommandAsync(std::move(request), [this, runtime_ptr, will_retry, completes_job, done = std::move(done)](
                                                   absl::StatusOr<FailCommandResult> result) mutable {
    executors_.completions->Post([this, runtime_ptr, will_retry, completes_job, result = std::move(result),
                                  done = std::move(done)]() mutable {
      if (!result.ok()) {
        return done(registry_->MarkWriteFailed(*runtime_ptr, result.status()));
      }
      PlanProgress progress;
      {
        MutexLock lock(&runtime_ptr->mu);
        runtime_ptr->updated_unix_ms = std::max(runtime_ptr->updated_unix_ms, UnixMillisNow());
        if (completes_job) {
          runtime_ptr->durable_state = JobState::kCompleted;
          progress = runtime_ptr->plan.Progress();
        }
      }
      if (completes_job) {
        registry_->NoteFinished(runtime_ptr->job_id);
        LogJobCompleted(runtime_ptr->job_id, progress);
      }
      NotifyListeners(*runtime_ptr);
      done(will_retry);
    });
  });
  return absl::OkStatus();
}

}  // namespace surfmap
