#include "storage/sqlite_writes.h"

#include <cmath>

#include "absl/strings/str_cat.h"
#include "storage/sqlite_rows.h"

namespace surfmap::sqlite {

absl::Status Annotate(const absl::Status& status, std::string_view context) {
  if (status.ok()) return status;
  return absl::Status(status.code(), absl::StrCat(std::string(context), ": ", status.message()));
}

// ---- Validation (runs on the caller's thread, before queuing) ----

absl::Status ValidateEvents(const std::vector<NewEvent>& events) {
  for (size_t i = 0; i < events.size(); ++i) {
    if (events[i].kind.empty()) {
      return absl::InvalidArgumentError(absl::StrCat("events[", i, "].kind is empty"));
    }
  }
  return absl::OkStatus();
}

absl::Status ValidateFit(const NewFit& fit, const std::string& where) {
  if (fit.estimator_name.empty()) {
    return absl::InvalidArgumentError(absl::StrCat(where, ".estimator_name is empty"));
  }
  if (fit.estimator_version.empty()) {
    return absl::InvalidArgumentError(absl::StrCat(where, ".estimator_version is empty"));
  }
  return absl::OkStatus();
}

// ---- Write steps (run on the writer thread, inside a savepoint) ----

absl::StatusOr<JobRecord> LoadJob(SqliteConnection& db, int64_t job_id) {
  static const std::string sql = absl::StrCat("SELECT ", kJobColumns, " FROM jobs WHERE id = ?1");
  SURFMAP_ASSIGN_OR_RETURN(SqliteStatement stmt, db.Prepare(sql));
  stmt.BindInt(1, job_id);
  SURFMAP_ASSIGN_OR_RETURN(bool found, stmt.Step());
  if (!found) return absl::NotFoundError(absl::StrCat("job ", job_id, " does not exist"));
  return ReadJob(stmt);
}

absl::StatusOr<CommandRecord> LoadCommand(SqliteConnection& db, int64_t command_id) {
  static const std::string sql =
      absl::StrCat("SELECT ", kCommandColumns, " FROM commands WHERE id = ?1");
  SURFMAP_ASSIGN_OR_RETURN(SqliteStatement stmt, db.Prepare(sql));
  stmt.BindInt(1, command_id);
  SURFMAP_ASSIGN_OR_RETURN(bool found, stmt.Step());
  if (!found) return absl::NotFoundError(absl::StrCat("command ", command_id, " does not exist"));
  return ReadCommand(stmt);
}

absl::Status InsertEvents(SqliteConnection& db, int64_t job_id,
                          const std::vector<NewEvent>& events, int64_t now) {
  for (size_t i = 0; i < events.size(); ++i) {
    SURFMAP_ASSIGN_OR_RETURN(
        SqliteStatement stmt,
        db.Prepare("INSERT INTO events (job_id, unix_ms, kind, detail_json) "
                   "VALUES (?1, ?2, ?3, ?4)"));
    if (job_id > 0) {
      stmt.BindInt(1, job_id);
    } else {
      stmt.BindNull(1);
    }
    stmt.BindInt(2, now).BindText(3, events[i].kind).BindText(4, events[i].detail_json);
    if (absl::Status s = stmt.Run(); !s.ok()) {
      return Annotate(s, absl::StrCat("events[", i, "] (kind '", events[i].kind, "')"));
    }
  }
  return absl::OkStatus();
}

absl::StatusOr<std::vector<int64_t>> InsertCommands(SqliteConnection& db, int64_t job_id,
                                                    const std::vector<NewCommand>& commands,
                                                    int64_t now, const std::string& field) {
  std::vector<int64_t> ids;
  ids.reserve(commands.size());
  for (size_t i = 0; i < commands.size(); ++i) {
    const NewCommand& c = commands[i];
    SURFMAP_ASSIGN_OR_RETURN(
        SqliteStatement stmt,
        db.Prepare("INSERT INTO commands (job_id, site_level, site_vertex, state, "
                   "created_unix_ms, command_json) VALUES (?1, ?2, ?3, 'pending', ?4, ?5)"));
    stmt.BindInt(1, job_id).BindInt(2, c.site_level).BindInt(3, c.site_vertex);
    stmt.BindInt(4, now).BindText(5, c.command_json);
    if (absl::Status s = stmt.Run(); !s.ok()) {
      return Annotate(s, absl::StrCat(field, "[", i, "] (site level ", c.site_level, " vertex ",
                                      c.site_vertex, ")"));
    }
    ids.push_back(db.LastInsertRowId());
  }
  return ids;
}

absl::StatusOr<int64_t> InsertAnsweredCommand(SqliteConnection& db, int64_t job_id, const NewCommand& c,
                                              const char* state, const std::string& owner, int64_t now,
                                              const std::string& field) {
  SURFMAP_ASSIGN_OR_RETURN(
      SqliteStatement stmt,
      db.Prepare("INSERT INTO commands (job_id, site_level, site_vertex, state, lease_owner, attempt, "
                 "created_unix_ms, command_json) VALUES (?1, ?2, ?3, ?4, ?5, 1, ?6, ?7)"));
  stmt.BindInt(1, job_id).BindInt(2, c.site_level).BindInt(3, c.site_vertex).BindText(4, state);
  stmt.BindText(5, owner).BindInt(6, now).BindText(7, c.command_json);
  if (absl::Status s = stmt.Run(); !s.ok()) {
    return Annotate(s, absl::StrCat(field, " (site level ", c.site_level, " vertex ", c.site_vertex, ")"));
  }
  return db.LastInsertRowId();
}

absl::Status CheckTakesImports(const JobRecord& job) {
  if (job.state == JobState::kCancelled || job.state == JobState::kCompleted) {
    return absl::FailedPreconditionError(absl::StrCat("job ", job.id, " is ", std::string(JobStateName(job.state)),
                                                      ": it takes no more traces, imported or not"));
  }
  return absl::OkStatus();
}

// Inserts the fit and returns it as the store now holds it, so writers answer
// with exactly what a later read gives (a NaN headline number reads as empty).
absl::StatusOr<FitRecord> InsertFit(SqliteConnection& db, int64_t trace_id, int32_t version,
                                    const NewFit& fit, int64_t now) {
  SURFMAP_ASSIGN_OR_RETURN(
      SqliteStatement stmt,
      db.Prepare("INSERT INTO fits (trace_id, version, estimator_name, estimator_version, "
                 "mu, a1, a2, sigma, created_unix_ms, options_json, result_json) "
                 "VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8, ?9, ?10, ?11)"));
  stmt.BindInt(1, trace_id).BindInt(2, version);
  stmt.BindText(3, fit.estimator_name).BindText(4, fit.estimator_version);
  stmt.BindOptionalDouble(5, fit.mu).BindOptionalDouble(6, fit.a1);
  stmt.BindOptionalDouble(7, fit.a2).BindOptionalDouble(8, fit.sigma);
  stmt.BindInt(9, now).BindText(10, fit.options_json).BindText(11, fit.result_json);
  if (absl::Status s = stmt.Run(); !s.ok()) {
    return Annotate(s, absl::StrCat("fit version ", version, " of trace ", trace_id));
  }
  auto stored = [](const std::optional<double>& v) {
    return v.has_value() && !std::isnan(*v) ? v : std::nullopt;  // as BindOptionalDouble wrote it
  };
  FitRecord r;
  r.id = db.LastInsertRowId();
  r.trace_id = trace_id;
  r.version = version;
  r.estimator_name = fit.estimator_name;
  r.estimator_version = fit.estimator_version;
  r.options_json = fit.options_json;
  r.result_json = fit.result_json;
  r.mu = stored(fit.mu);
  r.a1 = stored(fit.a1);
  r.a2 = stored(fit.a2);
  r.sigma = stored(fit.sigma);
  r.created_unix_ms = now;
  return r;
}

absl::Status SetJobState(SqliteConnection& db, const JobRecord& job, JobState to, int64_t now) {
  if (!IsJobTransitionAllowed(job.state, to)) {
    return absl::FailedPreconditionError(absl::StrCat("job ", job.id, " cannot go from ",
                                                      std::string(JobStateName(job.state)), " to ",
                                                      std::string(JobStateName(to))));
  }
  SURFMAP_ASSIGN_OR_RETURN(
      SqliteStatement stmt,
      db.Prepare("UPDATE jobs SET state = ?2, updated_unix_ms = ?3 WHERE id = ?1"));
  stmt.BindInt(1, job.id).BindText(2, std::string(JobStateName(to))).BindInt(3, now);
  return stmt.Run();
}

// The checkpoint's revision, or the last journal entry's when there is one.
absl::StatusOr<int64_t> CurrentPlanRevision(SqliteConnection& db, int64_t job_id) {
  SURFMAP_ASSIGN_OR_RETURN(
      SqliteStatement stmt,
      db.Prepare("SELECT MAX(p.revision, COALESCE((SELECT MAX(revision) FROM plan_journal "
                 "WHERE job_id = ?1), 0)) FROM plans p WHERE p.job_id = ?1"));
  stmt.BindInt(1, job_id);
  SURFMAP_ASSIGN_OR_RETURN(bool found, stmt.Step());
  if (!found) return absl::InternalError(absl::StrCat("job ", job_id, " has no plan row"));
  return stmt.ColumnInt(0);
}

namespace {

// The plan change that comes with an answer to a command (a trace or a
// failure): checked before anything is written, applied after.
struct PlanChange {
  const std::string& new_plan_json;
  const std::string& plan_journal_entry;
  int64_t expected_plan_revision;
  const std::vector<NewCommand>& new_commands;
  const std::optional<JobState>& new_job_state;
  const std::vector<NewEvent>& events;

  bool changes_plan() const { return !new_plan_json.empty() || !plan_journal_entry.empty(); }
};

// The command must be this job's, leased (to `lease_owner` when set), and the
// job still taking answers. Returns the job.
absl::StatusOr<JobRecord> CheckLeasedCommand(SqliteConnection& db, int64_t command_id, int64_t job_id,
                                             const std::string& lease_owner, const char* answer) {
  SURFMAP_ASSIGN_OR_RETURN(CommandRecord command, LoadCommand(db, command_id));
  if (command.job_id != job_id) {
    return absl::InvalidArgumentError(absl::StrCat("command ", command_id, " belongs to job ",
                                                   command.job_id, ", not job ", job_id));
  }
  SURFMAP_ASSIGN_OR_RETURN(JobRecord job, LoadJob(db, job_id));
  if (job.state == JobState::kCancelled || job.state == JobState::kCompleted) {
    return absl::FailedPreconditionError(absl::StrCat("job ", job.id, " is ",
                                                      std::string(JobStateName(job.state)),
                                                      ": it takes no more ", answer));
  }
  if (command.state != CommandState::kLeased) {
    return absl::FailedPreconditionError(
        absl::StrCat("command ", command.id, " is ", std::string(CommandStateName(command.state)),
                     ", not leased: only a leased command takes ", answer));
  }
  if (!lease_owner.empty() && lease_owner != command.lease_owner) {
    return absl::FailedPreconditionError(absl::StrCat(
        "command ", command.id, " is leased to '", command.lease_owner, "' (attempt ", command.attempt,
        "), not to '", lease_owner, "': the lease of '", lease_owner,
        "' expired and the command was leased again; nothing from '", lease_owner, "' was stored"));
  }
  return job;
}

// Returns the plan's current revision.
absl::StatusOr<int64_t> CheckPlanChange(SqliteConnection& db, const JobRecord& job, const PlanChange& change) {
  SURFMAP_ASSIGN_OR_RETURN(int64_t revision, CurrentPlanRevision(db, job.id));
  if (change.changes_plan() && change.expected_plan_revision > 0 &&
      change.expected_plan_revision != revision) {
    return absl::AbortedError(absl::StrCat(
        "plan of job ", job.id, " is at revision ", revision, ", not ",
        change.expected_plan_revision, ": another write changed it; re-read the plan and retry"));
  }
  if (change.new_job_state.has_value() && !IsJobTransitionAllowed(job.state, *change.new_job_state)) {
    return absl::FailedPreconditionError(absl::StrCat(
        "job ", job.id, " cannot go from ", std::string(JobStateName(job.state)), " to ",
        std::string(JobStateName(*change.new_job_state))));
  }
  return revision;
}

// Writes the plan, new commands, job state and events; updates *revision.
absl::Status ApplyPlanChange(SqliteConnection& db, const JobRecord& job, const PlanChange& change, int64_t now,
                             int64_t* revision, std::vector<int64_t>* new_command_ids) {
  if (!change.new_plan_json.empty()) {
    SURFMAP_ASSIGN_OR_RETURN(
        SqliteStatement stmt,
        db.Prepare("UPDATE plans SET plan_json = ?2, revision = ?4, "
                   "updated_unix_ms = ?3 WHERE job_id = ?1"));
    stmt.BindInt(1, job.id).BindText(2, change.new_plan_json).BindInt(3, now).BindInt(4, *revision + 1);
    SURFMAP_RETURN_IF_ERROR(Annotate(stmt.Run(), "new_plan_json"));
    SURFMAP_ASSIGN_OR_RETURN(SqliteStatement clear, db.Prepare("DELETE FROM plan_journal WHERE job_id = ?1"));
    clear.BindInt(1, job.id);
    SURFMAP_RETURN_IF_ERROR(Annotate(clear.Run(), "clearing the plan journal"));
    *revision += 1;
  } else if (!change.plan_journal_entry.empty()) {
    SURFMAP_ASSIGN_OR_RETURN(
        SqliteStatement stmt,
        db.Prepare("INSERT INTO plan_journal (job_id, revision, entry_json) VALUES (?1, ?2, ?3)"));
    stmt.BindInt(1, job.id).BindInt(2, *revision + 1).BindText(3, change.plan_journal_entry);
    SURFMAP_RETURN_IF_ERROR(Annotate(stmt.Run(), "plan_journal_entry"));
    *revision += 1;
  }
  SURFMAP_ASSIGN_OR_RETURN(*new_command_ids,
                           InsertCommands(db, job.id, change.new_commands, now, "new_commands"));
  if (change.new_job_state.has_value()) {
    SURFMAP_RETURN_IF_ERROR(SetJobState(db, job, *change.new_job_state, now));
  }
  return InsertEvents(db, job.id, change.events, now);
}

absl::Status SetCommandState(SqliteConnection& db, int64_t command_id, const char* state) {
  SURFMAP_ASSIGN_OR_RETURN(SqliteStatement stmt, db.Prepare("UPDATE commands SET state = ?2 WHERE id = ?1"));
  stmt.BindInt(1, command_id).BindText(2, state);
  return stmt.Run();
}

absl::StatusOr<FitRecord> LoadFit(SqliteConnection& db, int64_t trace_id, int32_t version) {
  static const std::string sql =
      absl::StrCat("SELECT ", kFitColumns, " FROM fits WHERE trace_id = ?1 AND version = ?2");
  SURFMAP_ASSIGN_OR_RETURN(SqliteStatement stmt, db.Prepare(sql));
  stmt.BindInt(1, trace_id).BindInt(2, version);
  SURFMAP_ASSIGN_OR_RETURN(bool found, stmt.Step());
  if (!found) return absl::NotFoundError(absl::StrCat("trace ", trace_id, " has no fit version ", version));
  return ReadFit(stmt);
}

// The command `owner` holds now in the job (the newest such lease that has
// not expired), if any.
absl::StatusOr<std::optional<CommandRecord>> CurrentLeaseOf(SqliteConnection& db, int64_t job_id,
                                                            const std::string& owner, int64_t now) {
  static const std::string sql = absl::StrCat(
      "SELECT ", kCommandColumns, " FROM commands WHERE job_id = ?1 AND state IN ('pending', 'leased') "
      "AND state = 'leased' AND lease_owner = ?2 AND lease_deadline_unix_ms > ?3 ORDER BY id DESC LIMIT 1");
  SURFMAP_ASSIGN_OR_RETURN(SqliteStatement stmt, db.Prepare(sql));
  stmt.BindInt(1, job_id).BindText(2, owner).BindInt(3, now);
  SURFMAP_ASSIGN_OR_RETURN(bool found, stmt.Step());
  if (!found) return std::optional<CommandRecord>();
  SURFMAP_ASSIGN_OR_RETURN(CommandRecord command, ReadCommand(stmt));
  return std::optional<CommandRecord>(std::move(command));
}

// The answer for a trace already stored (a retry, a repeated import): what
// the first write stored, its first fit and the plan's revision. Nothing is
// written.
absl::Status AnswerStoredTrace(SqliteConnection& db, int64_t job_id, int64_t trace_id, int64_t command_id,
                               int64_t received_unix_ms, std::string metadata_json, AcceptTraceResult* result) {
  result->trace_id = trace_id;
  result->command_id = command_id;
  result->already_accepted = true;
  result->accepted_unix_ms = received_unix_ms;
  result->metadata_json = std::move(metadata_json);
  SURFMAP_ASSIGN_OR_RETURN(result->plan_revision, CurrentPlanRevision(db, job_id));
  absl::StatusOr<FitRecord> fit = LoadFit(db, trace_id, 1);
  if (fit.ok()) {
    result->fit_id = fit->id;
    result->fit = std::move(*fit);
  } else if (fit.status().code() != absl::StatusCode::kNotFound) {
    return fit.status();
  }
  return absl::OkStatus();
}

// A command that already has a trace: this submission is a retry of it (the
// same rig, the same samples), or it is refused without writing anything.
absl::StatusOr<AcceptTraceResult> AnswerRepeatedSubmission(SqliteConnection& db, const EncodedTrace& in,
                                                           const TraceRecord& stored, std::string_view stored_blob) {
  const AcceptTraceRequest& req = in.request;
  if (stored.job_id != req.job_id) {
    return absl::InvalidArgumentError(
        absl::StrCat("command ", req.command_id, " belongs to job ", stored.job_id, ", not job ", req.job_id));
  }
  // A done command is never leased again: its last lease owner measured it.
  SURFMAP_ASSIGN_OR_RETURN(CommandRecord command, LoadCommand(db, req.command_id));
  const std::string& measured_by = command.lease_owner;
  if (!req.lease_owner.empty() && measured_by != req.lease_owner) {
    return absl::AlreadyExistsError(absl::StrCat(
        "command ", req.command_id, " was measured by rig '", measured_by, "' (trace ", stored.id,
        ") after the lease of '", req.lease_owner, "' expired; the trace of '", req.lease_owner,
        "' was not stored"));
  }
  if (stored.n_samples != in.n_samples || stored_blob != in.blob) {
    return absl::AlreadyExistsError(absl::StrCat(
        "command ", req.command_id, " already has trace ", stored.id, " from rig '", measured_by, "' (",
        stored.n_samples, " samples); this submission has ", in.n_samples,
        " samples that differ from it: a command takes one trace, so it was not stored"));
  }
  AcceptTraceResult result;
  SURFMAP_RETURN_IF_ERROR(
      AnswerStoredTrace(db, req.job_id, stored.id, req.command_id, stored.received_unix_ms, stored.metadata_json,
                        &result));
  if (req.lease_next.has_value()) {
    // The first write leased this rig its next command: hand back the same
    // one, so a retry never leaves an orphaned lease. Only when the rig holds
    // none any more (it expired) is a new one leased.
    SURFMAP_ASSIGN_OR_RETURN(result.next_command,
                             CurrentLeaseOf(db, req.job_id, req.lease_next->owner, req.lease_next->now_unix_ms));
    if (!result.next_command.has_value()) {
      SURFMAP_ASSIGN_OR_RETURN(result.next_command, LeaseWrite(db, *req.lease_next));
    }
  }
  return result;
}

}  // namespace

namespace {

// An import already stored in the job (the same file): its trace and first
// fit, as the first import answered. Nothing is written.
absl::StatusOr<std::optional<AcceptTraceResult>> FindImported(SqliteConnection& db, int64_t job_id,
                                                              const std::string& sha256) {
  SURFMAP_ASSIGN_OR_RETURN(SqliteStatement stmt,
                           db.Prepare("SELECT id, command_id, received_unix_ms, metadata_json FROM traces "
                                      "WHERE job_id = ?1 AND import_sha256 = ?2"));
  stmt.BindInt(1, job_id).BindText(2, sha256);
  SURFMAP_ASSIGN_OR_RETURN(bool found, stmt.Step());
  if (!found) return std::optional<AcceptTraceResult>();
  AcceptTraceResult result;
  SURFMAP_RETURN_IF_ERROR(AnswerStoredTrace(db, job_id, stmt.ColumnInt(0), stmt.ColumnInt(1), stmt.ColumnInt(2),
                                            stmt.ColumnText(3), &result));
  return std::optional<AcceptTraceResult>(std::move(result));
}

// The trace, its fit and the plan change: the rows every accepted trace
// writes, leased or imported.
absl::Status InsertAcceptedTrace(SqliteConnection& db, const EncodedTrace& in, const JobRecord& job,
                                 int64_t command_id, int64_t now, AcceptTraceResult* result) {
  const AcceptTraceRequest& req = in.request;
  const PlanChange change{req.new_plan_json, req.plan_journal_entry, req.expected_plan_revision,
                          req.new_commands, req.new_job_state, req.events};
  {
    SURFMAP_ASSIGN_OR_RETURN(
        SqliteStatement stmt,
        db.Prepare("INSERT INTO traces (command_id, job_id, n_samples, sample_encoding, "
                   "received_unix_ms, samples, metadata_json, import_sha256) VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8)"));
    stmt.BindInt(1, command_id).BindInt(2, req.job_id).BindInt(3, in.n_samples);
    stmt.BindInt(4, kSampleEncodingPackedLE).BindInt(5, now).BindBlob(6, in.blob).BindText(7, req.metadata_json);
    if (req.import.has_value()) {
      stmt.BindText(8, req.import->sha256);
    } else {
      stmt.BindNull(8);
    }
    SURFMAP_RETURN_IF_ERROR(Annotate(stmt.Run(), "storing trace"));
    result->trace_id = db.LastInsertRowId();
    result->accepted_unix_ms = now;
    result->command_id = command_id;
    result->metadata_json = req.metadata_json;
  }
  if (!req.frame.empty() && req.frame != "object") {
    // A trace sent in a rig's frame: which frame, and the registration it was
    // converted with (the samples above are as sent).
    SURFMAP_ASSIGN_OR_RETURN(
        SqliteStatement stmt,
        db.Prepare("INSERT INTO trace_frames (trace_id, frame, registration_id) VALUES (?1, ?2, ?3)"));
    stmt.BindInt(1, result->trace_id).BindText(2, req.frame).BindInt(3, req.registration_id);
    SURFMAP_RETURN_IF_ERROR(Annotate(stmt.Run(), "storing the trace's frame"));
  }
  // A leased command becomes done here; an import's was inserted done.
  if (!req.import.has_value()) SURFMAP_RETURN_IF_ERROR(SetCommandState(db, command_id, "done"));
  if (req.fit.has_value()) {
    SURFMAP_ASSIGN_OR_RETURN(FitRecord fit, InsertFit(db, result->trace_id, 1, *req.fit, now));
    result->fit_id = fit.id;
    result->fit = std::move(fit);
  }
  return ApplyPlanChange(db, job, change, now, &result->plan_revision, &result->new_command_ids);
}

absl::StatusOr<AcceptTraceResult> ImportTraceWrite(SqliteConnection& db, const EncodedTrace& in, int64_t now) {
  const AcceptTraceRequest& req = in.request;
  SURFMAP_ASSIGN_OR_RETURN(std::optional<AcceptTraceResult> stored, FindImported(db, req.job_id, req.import->sha256));
  if (stored.has_value()) return std::move(*stored);
  // Every check before any insert; the job loaded once.
  SURFMAP_ASSIGN_OR_RETURN(JobRecord job, LoadJob(db, req.job_id));
  SURFMAP_RETURN_IF_ERROR(CheckTakesImports(job));
  const PlanChange change{req.new_plan_json, req.plan_journal_entry, req.expected_plan_revision,
                          req.new_commands, req.new_job_state, req.events};
  AcceptTraceResult result;
  SURFMAP_ASSIGN_OR_RETURN(result.plan_revision, CheckPlanChange(db, job, change));
  // The implied command, stored done (measured by the source) in one row write.
  SURFMAP_ASSIGN_OR_RETURN(int64_t command_id, InsertAnsweredCommand(db, req.job_id, req.import->command, "done",
                                                                     req.import->source, now, "import.command"));
  SURFMAP_RETURN_IF_ERROR(InsertAcceptedTrace(db, in, job, command_id, now, &result));
  return result;
}

}  // namespace

absl::Status ValidateImport(const AcceptTraceRequest& request) {
  const TraceImport& import = *request.import;
  SURFMAP_RETURN_IF_ERROR(ValidateSha256(import.sha256, "import: sha256"));
  if (import.source.empty()) return absl::InvalidArgumentError("import: source must not be empty");
  if (request.command_id != 0 || !request.lease_owner.empty() || request.lease_next.has_value()) {
    return absl::InvalidArgumentError("import: an imported trace answers no leased command (command_id 0, "
                                      "no lease_owner, no lease_next)");
  }
  if (import.command.command_json.empty()) return absl::InvalidArgumentError("import: command_json is empty");
  return absl::OkStatus();
}

absl::Status ValidateFrame(const std::string& frame, int64_t registration_id) {
  if (frame.empty() || frame == "object") {
    if (registration_id != 0) {
      return absl::InvalidArgumentError(absl::StrCat("frame: a trace in the object's frame has no registration (got "
                                                     "registration_id ", registration_id, ")"));
    }
    return absl::OkStatus();
  }
  if (frame != "rig_base" && frame != "rig_base_sensor_forces") {
    return absl::InvalidArgumentError(absl::StrCat("frame: '", frame, "' is not a trace frame (object, "
                                                   "rig_base or rig_base_sensor_forces)"));
  }
  if (registration_id <= 0) {
    return absl::InvalidArgumentError(absl::StrCat("frame: a trace in frame '", frame,
                                                   "' needs the registration it was converted with (registration_id "
                                                   "must be positive, got ", registration_id, ")"));
  }
  return absl::OkStatus();
}

absl::Status ValidateSha256(const std::string& sha256, absl::string_view field) {
  if (sha256.size() != 64 || sha256.find_first_not_of("0123456789abcdef") != std::string::npos) {
    return absl::InvalidArgumentError(absl::StrCat(field, " must be 64 lower-case hex digits"));
  }
  return absl::OkStatus();
}

absl::StatusOr<AcceptTraceResult> AcceptTraceWrite(SqliteConnection& db, const EncodedTrace& in, int64_t now) {
  const AcceptTraceRequest& req = in.request;
  if (req.import.has_value()) return ImportTraceWrite(db, in, now);
  {
    static const std::string sql =
        absl::StrCat("SELECT ", kTraceColumns, ", samples FROM traces WHERE command_id = ?1");
    SURFMAP_ASSIGN_OR_RETURN(SqliteStatement stmt, db.Prepare(sql));
    stmt.BindInt(1, req.command_id);
    SURFMAP_ASSIGN_OR_RETURN(bool exists, stmt.Step());
    if (exists) {
      SURFMAP_ASSIGN_OR_RETURN(TraceRecord stored, ReadTrace(stmt, /*with_samples=*/false));
      return AnswerRepeatedSubmission(db, in, stored, stmt.ColumnBlob(kTraceColumnCount));
    }
  }

  AcceptTraceResult result;
  const PlanChange change{req.new_plan_json, req.plan_journal_entry, req.expected_plan_revision,
                          req.new_commands, req.new_job_state, req.events};
  SURFMAP_ASSIGN_OR_RETURN(JobRecord job,
                           CheckLeasedCommand(db, req.command_id, req.job_id, req.lease_owner, "traces"));
  SURFMAP_ASSIGN_OR_RETURN(result.plan_revision, CheckPlanChange(db, job, change));

  // All checks passed: the writes.
  SURFMAP_RETURN_IF_ERROR(InsertAcceptedTrace(db, in, job, req.command_id, now, &result));
  if (req.lease_next.has_value()) {
    SURFMAP_ASSIGN_OR_RETURN(result.next_command, LeaseWrite(db, *req.lease_next));
  }
  return result;
}

absl::StatusOr<FailCommandResult> FailCommandWrite(SqliteConnection& db, const FailCommandRequest& req,
                                                   int64_t now) {
  FailCommandResult result;
  const PlanChange change{req.new_plan_json, req.plan_journal_entry, req.expected_plan_revision,
                          req.new_commands, req.new_job_state, req.events};
  SURFMAP_ASSIGN_OR_RETURN(JobRecord job,
                           CheckLeasedCommand(db, req.command_id, req.job_id, req.lease_owner, "failure reports"));
  SURFMAP_ASSIGN_OR_RETURN(result.plan_revision, CheckPlanChange(db, job, change));
  SURFMAP_RETURN_IF_ERROR(SetCommandState(db, req.command_id, "failed"));
  SURFMAP_RETURN_IF_ERROR(ApplyPlanChange(db, job, change, now, &result.plan_revision, &result.new_command_ids));
  return result;
}

absl::Status ValidateLease(const LeaseRequest& request) {
  if (request.owner.empty()) return absl::InvalidArgumentError("lease owner is empty");
  if (request.lease_duration_ms <= 0) {
    return absl::InvalidArgumentError(absl::StrCat("lease_duration_ms must be > 0, got ", request.lease_duration_ms));
  }
  return absl::OkStatus();
}

// The lease itself, inside the caller's transaction: the oldest leasable
// command (pending, or leased with an expired lease) of a running job.
absl::StatusOr<std::optional<CommandRecord>> LeaseWrite(SqliteConnection& db, const LeaseRequest& request) {
  if (request.job_id != 0) {
    SURFMAP_ASSIGN_OR_RETURN(JobRecord job, LoadJob(db, request.job_id));
    (void)job;  // only its existence matters: an unknown job is NotFound
  }
  // The state IN (...) term matches the partial indexes commands_leasable
  // (any job) and commands_leasable_by_job (one job: without it a lease
  // would scan the pending commands of every older running job).
  SURFMAP_ASSIGN_OR_RETURN(
      SqliteStatement pick,
      db.Prepare(request.job_id == 0
                     ? "SELECT c.id FROM commands c JOIN jobs j ON j.id = c.job_id "
                       "WHERE c.state IN ('pending', 'leased') "
                       "AND (c.state = 'pending' OR c.lease_deadline_unix_ms <= ?1) "
                       "AND j.state = 'running' ORDER BY c.id LIMIT 1"
                     : "SELECT c.id FROM commands c JOIN jobs j ON j.id = c.job_id "
                       "WHERE c.job_id = ?2 AND c.state IN ('pending', 'leased') "
                       "AND (c.state = 'pending' OR c.lease_deadline_unix_ms <= ?1) "
                       "AND j.state = 'running' ORDER BY c.id LIMIT 1"));
  pick.BindInt(1, request.now_unix_ms);
  if (request.job_id != 0) pick.BindInt(2, request.job_id);
  SURFMAP_ASSIGN_OR_RETURN(bool found, pick.Step());
  if (!found) return std::optional<CommandRecord>();
  const int64_t command_id = pick.ColumnInt(0);
  {
    SURFMAP_ASSIGN_OR_RETURN(
        SqliteStatement stmt,
        db.Prepare("UPDATE commands SET state = 'leased', lease_owner = ?2, "
                   "lease_deadline_unix_ms = ?3, attempt = attempt + 1 WHERE id = ?1"));
    stmt.BindInt(1, command_id).BindText(2, request.owner);
    stmt.BindInt(3, request.now_unix_ms + request.lease_duration_ms);
    SURFMAP_RETURN_IF_ERROR(stmt.Run());
  }
  SURFMAP_ASSIGN_OR_RETURN(CommandRecord command, LoadCommand(db, command_id));
  return std::optional<CommandRecord>(std::move(command));
}
}  // namespace surfmap::sqlite
