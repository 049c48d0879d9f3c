#include "storage/sqlite_store.h"

#include <chrono>
#include <set>
#include <utility>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"
#include "storage/schema.h"

namespace surfmap {
namespace {

#define SURFMAP_RETURN_IF_ERROR(expr)            \
  do {                                           \
    if (absl::Status _s = (expr); !_s.ok()) {    \
      return _s;                                 \
    }                                            \
  } while (0)

#define SURFMAP_CONCAT_INNER(a, b) a##b
#define SURFMAP_CONCAT(a, b) SURFMAP_CONCAT_INNER(a, b)
#define SURFMAP_ASSIGN_OR_RETURN(lhs, expr) \
  SURFMAP_ASSIGN_OR_RETURN_IMPL(SURFMAP_CONCAT(_status_or_, __LINE__), lhs, expr)
#define SURFMAP_ASSIGN_OR_RETURN_IMPL(tmp, lhs, expr) \
  auto tmp = (expr);                                  \
  if (!tmp.ok()) return tmp.status();                 \
  lhs = std::move(*tmp)

int64_t SystemNowUnixMs() {
  return std::chrono::duration_cast<std::chrono::milliseconds>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}

// Adds context to an error without changing its code.
absl::Status Annotate(const absl::Status& status, absl::string_view context) {
  if (status.ok()) return status;
  return absl::Status(status.code(), absl::StrCat(context, ": ", status.message()));
}

// ---- Row readers (column lists and readers kept side by side) ----

constexpr char kObjectColumns[] =
    "id, name, mesh_format, control_vertices, control_faces, created_unix_ms";

ObjectRecord ReadObject(const SqliteStatement& s) {
  ObjectRecord r;
  r.id = s.ColumnInt(0);
  r.name = s.ColumnText(1);
  r.mesh_format = s.ColumnText(2);
  r.control_vertices = s.ColumnInt(3);
  r.control_faces = s.ColumnInt(4);
  r.created_unix_ms = s.ColumnInt(5);
  return r;
}

constexpr char kJobColumns[] =
    "id, object_id, state, params_json, created_unix_ms, updated_unix_ms";

absl::StatusOr<JobRecord> ReadJob(const SqliteStatement& s) {
  JobRecord r;
  r.id = s.ColumnInt(0);
  r.object_id = s.ColumnInt(1);
  SURFMAP_ASSIGN_OR_RETURN(r.state, ParseJobState(s.ColumnText(2)));
  r.params_json = s.ColumnText(3);
  r.created_unix_ms = s.ColumnInt(4);
  r.updated_unix_ms = s.ColumnInt(5);
  return r;
}

constexpr char kCommandColumns[] =
    "id, job_id, site_level, site_vertex, command_json, state, lease_owner, "
    "lease_deadline_unix_ms, attempt, created_unix_ms";

absl::StatusOr<CommandRecord> ReadCommand(const SqliteStatement& s) {
  CommandRecord r;
  r.id = s.ColumnInt(0);
  r.job_id = s.ColumnInt(1);
  r.site_level = static_cast<int32_t>(s.ColumnInt(2));
  r.site_vertex = s.ColumnInt(3);
  r.command_json = s.ColumnText(4);
  SURFMAP_ASSIGN_OR_RETURN(r.state, ParseCommandState(s.ColumnText(5)));
  r.lease_owner = s.ColumnText(6);
  r.lease_deadline_unix_ms = s.ColumnInt(7);
  r.attempt = static_cast<int32_t>(s.ColumnInt(8));
  r.created_unix_ms = s.ColumnInt(9);
  return r;
}

// Column 6 (samples) is selected only when samples are wanted.
constexpr char kTraceColumns[] =
    "id, command_id, job_id, n_samples, sample_encoding, received_unix_ms";

absl::StatusOr<TraceRecord> ReadTrace(const SqliteStatement& s, bool with_samples) {
  TraceRecord r;
  r.id = s.ColumnInt(0);
  r.command_id = s.ColumnInt(1);
  r.job_id = s.ColumnInt(2);
  r.n_samples = s.ColumnInt(3);
  r.received_unix_ms = s.ColumnInt(5);
  if (with_samples) {
    if (s.ColumnInt(4) != kSampleEncodingPackedLE) {
      return absl::InternalError(absl::StrCat("trace ", r.id, " has unknown sample encoding ",
                                              s.ColumnInt(4)));
    }
    absl::StatusOr<std::vector<StoredSample>> samples = DecodeSamples(s.ColumnBlob(6));
    if (!samples.ok() || static_cast<int64_t>(samples->size()) != r.n_samples) {
      return absl::DataLossError(absl::StrCat(
          "trace ", r.id, ": stored samples do not decode to n_samples=", r.n_samples,
          samples.ok() ? "" : absl::StrCat(" (", samples.status().message(), ")")));
    }
    r.samples = std::move(*samples);
  }
  return r;
}

constexpr char kFitColumns[] =
    "id, trace_id, version, estimator_name, estimator_version, options_json, result_json, "
    "mu, a1, a2, sigma, created_unix_ms";

FitRecord ReadFit(const SqliteStatement& s) {
  FitRecord r;
  r.id = s.ColumnInt(0);
  r.trace_id = s.ColumnInt(1);
  r.version = static_cast<int32_t>(s.ColumnInt(2));
  r.estimator_name = s.ColumnText(3);
  r.estimator_version = s.ColumnText(4);
  r.options_json = s.ColumnText(5);
  r.result_json = s.ColumnText(6);
  r.mu = s.ColumnOptionalDouble(7);
  r.a1 = s.ColumnOptionalDouble(8);
  r.a2 = s.ColumnOptionalDouble(9);
  r.sigma = s.ColumnOptionalDouble(10);
  r.created_unix_ms = s.ColumnInt(11);
  return r;
}

constexpr char kEventColumns[] = "id, job_id, unix_ms, kind, detail_json";

EventRecord ReadEvent(const SqliteStatement& s) {
  EventRecord r;
  r.id = s.ColumnInt(0);
  r.job_id = s.ColumnIsNull(1) ? 0 : s.ColumnInt(1);
  r.unix_ms = s.ColumnInt(2);
  r.kind = s.ColumnText(3);
  r.detail_json = s.ColumnText(4);
  return r;
}

// Steps a statement and collects every row with `read` (which returns T or
// StatusOr<T>).
template <typename T, typename ReadRow>
absl::StatusOr<std::vector<T>> CollectRows(SqliteStatement& stmt, ReadRow read) {
  std::vector<T> rows;
  while (true) {
    SURFMAP_ASSIGN_OR_RETURN(bool has_row, stmt.Step());
    if (!has_row) return rows;
    if constexpr (std::is_same_v<decltype(read(stmt)), T>) {
      rows.push_back(read(stmt));
    } else {
      SURFMAP_ASSIGN_OR_RETURN(T row, read(stmt));
      rows.push_back(std::move(row));
    }
  }
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
    return absl::FailedPreconditionError(
        absl::StrCat("command ", command.id, " is leased to '", command.lease_owner,
                     "', not to '", lease_owner, "'"));
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

// AcceptTrace with the samples already encoded (so the writer thread only copies).
struct EncodedTrace {
  AcceptTraceRequest request;  // samples moved out
  int64_t n_samples = 0;
  std::string blob;
};

absl::StatusOr<AcceptTraceResult> AcceptTraceWrite(SqliteConnection& db, const EncodedTrace& in,
                                                   int64_t now) {
  const AcceptTraceRequest& req = in.request;
  AcceptTraceResult result;

  // Idempotency: a retry after a lost reply gets the stored ids back.
  {
    SURFMAP_ASSIGN_OR_RETURN(
        SqliteStatement stmt,
        db.Prepare("SELECT t.id, t.job_id, (SELECT f.id FROM fits f WHERE f.trace_id = t.id "
                   "AND f.version = 1) FROM traces t WHERE t.command_id = ?1"));
    stmt.BindInt(1, req.command_id);
    SURFMAP_ASSIGN_OR_RETURN(bool exists, stmt.Step());
    if (exists) {
      if (stmt.ColumnInt(1) != req.job_id) {
        return absl::InvalidArgumentError(
            absl::StrCat("command ", req.command_id, " belongs to job ", stmt.ColumnInt(1),
                         ", not job ", req.job_id));
      }
      result.trace_id = stmt.ColumnInt(0);
      result.fit_id = stmt.ColumnIsNull(2) ? 0 : stmt.ColumnInt(2);
      result.already_accepted = true;
      SURFMAP_ASSIGN_OR_RETURN(result.plan_revision, CurrentPlanRevision(db, req.job_id));
      return result;
    }
  }

  const PlanChange change{req.new_plan_json, req.plan_journal_entry, req.expected_plan_revision,
                          req.new_commands, req.new_job_state, req.events};
  SURFMAP_ASSIGN_OR_RETURN(JobRecord job,
                           CheckLeasedCommand(db, req.command_id, req.job_id, req.lease_owner, "traces"));
  SURFMAP_ASSIGN_OR_RETURN(result.plan_revision, CheckPlanChange(db, job, change));

  // All checks passed: the writes.
  {
    SURFMAP_ASSIGN_OR_RETURN(
        SqliteStatement stmt,
        db.Prepare("INSERT INTO traces (command_id, job_id, n_samples, sample_encoding, "
                   "received_unix_ms, samples) VALUES (?1, ?2, ?3, ?4, ?5, ?6)"));
    stmt.BindInt(1, req.command_id).BindInt(2, req.job_id).BindInt(3, in.n_samples);
    stmt.BindInt(4, kSampleEncodingPackedLE).BindInt(5, now).BindBlob(6, in.blob);
    SURFMAP_RETURN_IF_ERROR(Annotate(stmt.Run(), "storing trace"));
    result.trace_id = db.LastInsertRowId();
    result.accepted_unix_ms = now;
  }
  SURFMAP_RETURN_IF_ERROR(SetCommandState(db, req.command_id, "done"));
  if (req.fit.has_value()) {
    SURFMAP_ASSIGN_OR_RETURN(FitRecord fit, InsertFit(db, result.trace_id, 1, *req.fit, now));
    result.fit_id = fit.id;
    result.fit = std::move(fit);
  }
  SURFMAP_RETURN_IF_ERROR(ApplyPlanChange(db, job, change, now, &result.plan_revision, &result.new_command_ids));
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

}  // namespace

// ---- Open / close ----

SqliteStore::SqliteStore(std::string path, SqliteStoreOptions options,
                         std::unique_ptr<WalCheckpointer> checkpointer,
                         std::unique_ptr<GroupCommitWriter> writer)
    : path_(std::move(path)),
      options_(std::move(options)),
      checkpointer_(std::move(checkpointer)),
      writer_(std::move(writer)),
      readers_(path_, options_.read_connections, options_.busy_timeout_ms) {}

SqliteStore::~SqliteStore() = default;

absl::StatusOr<std::unique_ptr<SqliteStore>> SqliteStore::Open(const std::string& path,
                                                               SqliteStoreOptions options) {
  if (!options.clock) options.clock = SystemNowUnixMs;
  if (options.writer.max_batch < 1) {
    return absl::InvalidArgumentError(
        absl::StrCat("writer.max_batch must be >= 1, got ", options.writer.max_batch));
  }
  SqliteOpenOptions open_options;
  open_options.busy_timeout_ms = options.busy_timeout_ms;
  open_options.page_size = options.page_size;
  SURFMAP_ASSIGN_OR_RETURN(std::unique_ptr<SqliteConnection> db,
                           SqliteConnection::Open(path, open_options));
  SURFMAP_RETURN_IF_ERROR(ApplyMigrations(*db, SchemaMigrations()));
  std::unique_ptr<WalCheckpointer> checkpointer;
  if (options.background_checkpoint) {
    SURFMAP_ASSIGN_OR_RETURN(checkpointer, WalCheckpointer::Start(path, *db, options.checkpoint));
  }
  auto writer = std::make_unique<GroupCommitWriter>(std::move(db), options.writer);
  return std::unique_ptr<SqliteStore>(new SqliteStore(
      path, std::move(options), std::move(checkpointer), std::move(writer)));
}

// ---- Objects ----

absl::StatusOr<int64_t> SqliteStore::CreateObject(const NewObject& object) {
  if (object.mesh_format != "obj" && object.mesh_format != "ply") {
    return absl::InvalidArgumentError(absl::StrCat("mesh_format must be \"obj\" or \"ply\", got \"",
                                                   object.mesh_format, "\""));
  }
  if (object.mesh_bytes.empty()) return absl::InvalidArgumentError("mesh_bytes is empty");
  if (object.control_vertices < 0 || object.control_faces < 0) {
    return absl::InvalidArgumentError("control_vertices and control_faces must be >= 0");
  }
  const int64_t now = Now();
  return writer_->Run<int64_t>([&object, now](SqliteConnection& db) -> absl::StatusOr<int64_t> {
    SURFMAP_ASSIGN_OR_RETURN(
        SqliteStatement stmt,
        db.Prepare("INSERT INTO objects (name, mesh_format, control_vertices, control_faces, "
                   "created_unix_ms, mesh_bytes) VALUES (?1, ?2, ?3, ?4, ?5, ?6)"));
    stmt.BindText(1, object.name).BindText(2, object.mesh_format);
    stmt.BindInt(3, object.control_vertices).BindInt(4, object.control_faces);
    stmt.BindInt(5, now).BindBlob(6, object.mesh_bytes);
    SURFMAP_RETURN_IF_ERROR(stmt.Run());
    return db.LastInsertRowId();
  });
}

absl::StatusOr<ObjectRecord> SqliteStore::GetObject(int64_t object_id, bool include_mesh) {
  static const std::string sql_with =
      absl::StrCat("SELECT ", kObjectColumns, ", mesh_bytes FROM objects WHERE id = ?1");
  static const std::string sql_without =
      absl::StrCat("SELECT ", kObjectColumns, " FROM objects WHERE id = ?1");
  SURFMAP_ASSIGN_OR_RETURN(ReadConnectionPool::Loan db, readers_.Borrow());
  SURFMAP_ASSIGN_OR_RETURN(SqliteStatement stmt,
                           db->Prepare(include_mesh ? sql_with : sql_without));
  stmt.BindInt(1, object_id);
  SURFMAP_ASSIGN_OR_RETURN(bool found, stmt.Step());
  if (!found) return absl::NotFoundError(absl::StrCat("object ", object_id, " does not exist"));
  ObjectRecord record = ReadObject(stmt);
  if (include_mesh) record.mesh_bytes = std::string(stmt.ColumnBlob(6));
  return record;
}

absl::StatusOr<std::vector<ObjectRecord>> SqliteStore::ListObjects() {
  static const std::string sql = absl::StrCat("SELECT ", kObjectColumns, " FROM objects ORDER BY id");
  SURFMAP_ASSIGN_OR_RETURN(ReadConnectionPool::Loan db, readers_.Borrow());
  SURFMAP_ASSIGN_OR_RETURN(SqliteStatement stmt, db->Prepare(sql));
  return CollectRows<ObjectRecord>(stmt, ReadObject);
}

// ---- Jobs and plans ----

absl::StatusOr<CreatedJob> SqliteStore::CreateJob(const NewJob& job) {
  if (job.plan_json.empty()) return absl::InvalidArgumentError("plan_json is empty");
  SURFMAP_RETURN_IF_ERROR(ValidateEvents(job.events));
  const int64_t now = Now();
  return writer_->Run<CreatedJob>([&job, now](SqliteConnection& db) -> absl::StatusOr<CreatedJob> {
    {
      SURFMAP_ASSIGN_OR_RETURN(SqliteStatement stmt,
                               db.Prepare("SELECT 1 FROM objects WHERE id = ?1"));
      stmt.BindInt(1, job.object_id);
      SURFMAP_ASSIGN_OR_RETURN(bool found, stmt.Step());
      if (!found) {
        return absl::NotFoundError(absl::StrCat("object ", job.object_id, " does not exist"));
      }
    }
    CreatedJob created;
    {
      SURFMAP_ASSIGN_OR_RETURN(
          SqliteStatement stmt,
          db.Prepare("INSERT INTO jobs (object_id, state, params_json, created_unix_ms, "
                     "updated_unix_ms) VALUES (?1, 'running', ?2, ?3, ?3)"));
      stmt.BindInt(1, job.object_id).BindText(2, job.params_json).BindInt(3, now);
      SURFMAP_RETURN_IF_ERROR(Annotate(stmt.Run(), "params_json"));
    }
    created.job.id = db.LastInsertRowId();
    created.job.object_id = job.object_id;
    created.job.state = JobState::kRunning;
    created.job.params_json = job.params_json;
    created.job.created_unix_ms = created.job.updated_unix_ms = now;
    {
      SURFMAP_ASSIGN_OR_RETURN(
          SqliteStatement stmt,
          db.Prepare("INSERT INTO plans (job_id, revision, updated_unix_ms, plan_json) "
                     "VALUES (?1, 1, ?2, ?3)"));
      stmt.BindInt(1, created.job.id).BindInt(2, now).BindText(3, job.plan_json);
      SURFMAP_RETURN_IF_ERROR(Annotate(stmt.Run(), "plan_json"));
    }
    SURFMAP_ASSIGN_OR_RETURN(created.command_ids,
                             InsertCommands(db, created.job.id, job.commands, now, "commands"));
    SURFMAP_RETURN_IF_ERROR(InsertEvents(db, created.job.id, job.events, now));
    return created;
  });
}

absl::StatusOr<JobRecord> SqliteStore::GetJob(int64_t job_id) {
  SURFMAP_ASSIGN_OR_RETURN(ReadConnectionPool::Loan db, readers_.Borrow());
  return LoadJob(*db, job_id);
}

absl::StatusOr<std::vector<JobRecord>> SqliteStore::ListJobs(int64_t object_id) {
  static const std::string sql = absl::StrCat(
      "SELECT ", kJobColumns, " FROM jobs WHERE ?1 = 0 OR object_id = ?1 ORDER BY id");
  SURFMAP_ASSIGN_OR_RETURN(ReadConnectionPool::Loan db, readers_.Borrow());
  SURFMAP_ASSIGN_OR_RETURN(SqliteStatement stmt, db->Prepare(sql));
  stmt.BindInt(1, object_id);
  return CollectRows<JobRecord>(stmt, ReadJob);
}

absl::StatusOr<JobRecord> SqliteStore::UpdateJobState(const JobStateChange& change) {
  SURFMAP_RETURN_IF_ERROR(ValidateEvents(change.events));
  const int64_t now = Now();
  return writer_->Run<JobRecord>([&change, now](SqliteConnection& db) -> absl::StatusOr<JobRecord> {
    SURFMAP_ASSIGN_OR_RETURN(JobRecord job, LoadJob(db, change.job_id));
    SURFMAP_RETURN_IF_ERROR(SetJobState(db, job, change.new_state, now));
    SURFMAP_RETURN_IF_ERROR(InsertEvents(db, job.id, change.events, now));
    job.state = change.new_state;
    job.updated_unix_ms = now;
    return job;
  });
}

absl::StatusOr<PlanRecord> SqliteStore::GetPlan(int64_t job_id) {
  SURFMAP_ASSIGN_OR_RETURN(ReadConnectionPool::Loan db, readers_.Borrow());
  SURFMAP_ASSIGN_OR_RETURN(
      SqliteStatement stmt,
      db->Prepare("SELECT job_id, plan_json, revision, updated_unix_ms FROM plans WHERE job_id = ?1"));
  stmt.BindInt(1, job_id);
  SURFMAP_ASSIGN_OR_RETURN(bool found, stmt.Step());
  if (!found) return absl::NotFoundError(absl::StrCat("job ", job_id, " does not exist"));
  PlanRecord plan;
  plan.job_id = stmt.ColumnInt(0);
  plan.plan_json = stmt.ColumnText(1);
  plan.revision = stmt.ColumnInt(2);
  plan.updated_unix_ms = stmt.ColumnInt(3);
  // Same snapshot as the checkpoint: `stmt` is still open (stepped, not
  // reset), so SQLite keeps this connection's read transaction across both
  // statements and no write can slip in between them.
  SURFMAP_ASSIGN_OR_RETURN(
      SqliteStatement journal,
      db->Prepare("SELECT revision, entry_json FROM plan_journal WHERE job_id = ?1 ORDER BY revision"));
  journal.BindInt(1, job_id);
  while (true) {
    SURFMAP_ASSIGN_OR_RETURN(bool more, journal.Step());
    if (!more) break;
    if (journal.ColumnInt(0) != plan.revision + 1) {
      return absl::DataLossError(absl::StrCat("plan of job ", job_id, ": journal entry at revision ",
                                              journal.ColumnInt(0), " does not follow revision ", plan.revision));
    }
    plan.journal.push_back(journal.ColumnText(1));
    plan.revision += 1;
  }
  return plan;
}

// ---- Commands ----

void SqliteStore::LeaseNextCommandAsync(const LeaseRequest& request, LeaseCallback done) {
  if (absl::Status s = ValidateLease(request); !s.ok()) {
    done(std::move(s));
    return;
  }
  writer_->SubmitForResult<std::optional<CommandRecord>>(
      [request](SqliteConnection& db) { return LeaseWrite(db, request); }, std::move(done));
}

absl::StatusOr<CommandRecord> SqliteStore::GetCommand(int64_t command_id) {
  SURFMAP_ASSIGN_OR_RETURN(ReadConnectionPool::Loan db, readers_.Borrow());
  return LoadCommand(*db, command_id);
}

absl::StatusOr<std::vector<CommandRecord>> SqliteStore::ListCommands(int64_t job_id) {
  static const std::string sql =
      absl::StrCat("SELECT ", kCommandColumns, " FROM commands WHERE job_id = ?1 ORDER BY id");
  SURFMAP_ASSIGN_OR_RETURN(ReadConnectionPool::Loan db, readers_.Borrow());
  SURFMAP_RETURN_IF_ERROR(LoadJob(*db, job_id).status());
  SURFMAP_ASSIGN_OR_RETURN(SqliteStatement stmt, db->Prepare(sql));
  stmt.BindInt(1, job_id);
  return CollectRows<CommandRecord>(stmt, ReadCommand);
}

absl::StatusOr<LeasedCounts> SqliteStore::CountLeasedCommands(int64_t job_id, int64_t now_unix_ms) {
  SURFMAP_ASSIGN_OR_RETURN(ReadConnectionPool::Loan db, readers_.Borrow());
  SURFMAP_RETURN_IF_ERROR(LoadJob(*db, job_id).status());
  // The state IN (...) term lets the partial index commands_leasable_by_job
  // serve this: it holds only the job's pending and leased commands.
  SURFMAP_ASSIGN_OR_RETURN(
      SqliteStatement stmt,
      db->Prepare("SELECT site_level, COUNT(*) FROM commands WHERE job_id = ?1 "
                  "AND state IN ('pending', 'leased') AND state = 'leased' AND lease_deadline_unix_ms > ?2 "
                  "GROUP BY site_level"));
  stmt.BindInt(1, job_id).BindInt(2, now_unix_ms);
  LeasedCounts counts;
  while (true) {
    SURFMAP_ASSIGN_OR_RETURN(bool row, stmt.Step());
    if (!row) break;
    const int n = static_cast<int>(stmt.ColumnInt(1));
    counts.by_level[static_cast<int>(stmt.ColumnInt(0))] = n;
    counts.total += n;
  }
  return counts;
}

// ---- Traces ----

void SqliteStore::AcceptTraceAsync(AcceptTraceRequest request, AcceptTraceCallback done) {
  if (request.samples.empty()) {
    done(absl::InvalidArgumentError(
        absl::StrCat("trace for command ", request.command_id, " has no samples")));
    return;
  }
  if (request.fit.has_value()) {
    if (absl::Status s = ValidateFit(*request.fit, "fit"); !s.ok()) {
      done(std::move(s));
      return;
    }
  }
  if (absl::Status s = ValidateEvents(request.events); !s.ok()) {
    done(std::move(s));
    return;
  }
  if (request.lease_next.has_value()) {
    if (absl::Status s = ValidateLease(*request.lease_next); !s.ok()) {
      done(std::move(s));
      return;
    }
  }
  // Encode here, on the caller's thread: the writer thread is the bottleneck.
  auto encoded = std::make_shared<EncodedTrace>();
  encoded->n_samples = static_cast<int64_t>(request.samples.size());
  encoded->blob = EncodeSamples(request.samples);
  request.samples = {};
  encoded->request = std::move(request);
  const int64_t now = Now();
  writer_->SubmitForResult<AcceptTraceResult>(
      [encoded, now](SqliteConnection& db) -> absl::StatusOr<AcceptTraceResult> {
        absl::StatusOr<AcceptTraceResult> result = AcceptTraceWrite(db, *encoded, now);
        if (!result.ok()) {
          return Annotate(result.status(),
                          absl::StrCat("AcceptTrace(command ", encoded->request.command_id, ")"));
        }
        if (encoded->request.lease_next.has_value()) {
          absl::StatusOr<std::optional<CommandRecord>> next = LeaseWrite(db, *encoded->request.lease_next);
          if (!next.ok()) {
            return Annotate(next.status(), absl::StrCat("AcceptTrace(command ", encoded->request.command_id,
                                                        "): leasing the next command"));
          }
          result->next_command = std::move(*next);
        }
        return result;
      },
      std::move(done));
}

void SqliteStore::FailCommandAsync(FailCommandRequest request, FailCommandCallback done) {
  if (absl::Status s = ValidateEvents(request.events); !s.ok()) {
    done(std::move(s));
    return;
  }
  auto shared = std::make_shared<FailCommandRequest>(std::move(request));
  const int64_t now = Now();
  writer_->SubmitForResult<FailCommandResult>(
      [shared, now](SqliteConnection& db) -> absl::StatusOr<FailCommandResult> {
        absl::StatusOr<FailCommandResult> result = FailCommandWrite(db, *shared, now);
        if (!result.ok()) {
          return Annotate(result.status(), absl::StrCat("FailCommand(command ", shared->command_id, ")"));
        }
        return result;
      },
      std::move(done));
}

absl::StatusOr<TraceRecord> SqliteStore::GetTrace(int64_t trace_id, bool include_samples) {
  static const std::string sql_with =
      absl::StrCat("SELECT ", kTraceColumns, ", samples FROM traces WHERE id = ?1");
  static const std::string sql_without =
      absl::StrCat("SELECT ", kTraceColumns, " FROM traces WHERE id = ?1");
  SURFMAP_ASSIGN_OR_RETURN(ReadConnectionPool::Loan db, readers_.Borrow());
  SURFMAP_ASSIGN_OR_RETURN(SqliteStatement stmt,
                           db->Prepare(include_samples ? sql_with : sql_without));
  stmt.BindInt(1, trace_id);
  SURFMAP_ASSIGN_OR_RETURN(bool found, stmt.Step());
  if (!found) return absl::NotFoundError(absl::StrCat("trace ", trace_id, " does not exist"));
  return ReadTrace(stmt, include_samples);
}

absl::StatusOr<std::vector<TraceRecord>> SqliteStore::ListTraces(int64_t job_id,
                                                                 bool include_samples) {
  static const std::string sql_with = absl::StrCat(
      "SELECT ", kTraceColumns, ", samples FROM traces WHERE job_id = ?1 ORDER BY id");
  static const std::string sql_without =
      absl::StrCat("SELECT ", kTraceColumns, " FROM traces WHERE job_id = ?1 ORDER BY id");
  SURFMAP_ASSIGN_OR_RETURN(ReadConnectionPool::Loan db, readers_.Borrow());
  SURFMAP_RETURN_IF_ERROR(LoadJob(*db, job_id).status());
  SURFMAP_ASSIGN_OR_RETURN(SqliteStatement stmt,
                           db->Prepare(include_samples ? sql_with : sql_without));
  stmt.BindInt(1, job_id);
  return CollectRows<TraceRecord>(
      stmt, [include_samples](const SqliteStatement& s) { return ReadTrace(s, include_samples); });
}

absl::StatusOr<JobActivity> SqliteStore::GetJobActivity(int64_t job_id) {
  // traces_by_job and events_by_job (job_id, id) serve both lookups.
  static const std::string latest_trace =
      absl::StrCat("SELECT ", kTraceColumns, " FROM traces WHERE job_id = ?1 ORDER BY id DESC LIMIT 1");
  SURFMAP_ASSIGN_OR_RETURN(ReadConnectionPool::Loan db, readers_.Borrow());
  SURFMAP_RETURN_IF_ERROR(LoadJob(*db, job_id).status());
  JobActivity activity;
  {
    SURFMAP_ASSIGN_OR_RETURN(SqliteStatement stmt, db->Prepare(latest_trace));
    stmt.BindInt(1, job_id);
    SURFMAP_ASSIGN_OR_RETURN(bool found, stmt.Step());
    if (found) {
      SURFMAP_ASSIGN_OR_RETURN(TraceRecord trace, ReadTrace(stmt, /*with_samples=*/false));
      activity.latest_trace = std::move(trace);
    }
  }
  {
    SURFMAP_ASSIGN_OR_RETURN(SqliteStatement stmt, db->Prepare("SELECT MAX(unix_ms) FROM events WHERE job_id = ?1"));
    stmt.BindInt(1, job_id);
    SURFMAP_ASSIGN_OR_RETURN(bool found, stmt.Step());
    if (found && !stmt.ColumnIsNull(0)) activity.last_event_unix_ms = stmt.ColumnInt(0);
  }
  return activity;
}

// ---- Fits ----

absl::StatusOr<FitRecord> SqliteStore::GetFit(int64_t trace_id, int32_t version) {
  static const std::string sql = absl::StrCat(
      "SELECT ", kFitColumns,
      " FROM fits WHERE trace_id = ?1 AND (?2 = 0 OR version = ?2) ORDER BY version DESC LIMIT 1");
  if (version < 0) {
    return absl::InvalidArgumentError(absl::StrCat("fit version must be >= 0, got ", version));
  }
  SURFMAP_ASSIGN_OR_RETURN(ReadConnectionPool::Loan db, readers_.Borrow());
  SURFMAP_ASSIGN_OR_RETURN(SqliteStatement stmt, db->Prepare(sql));
  stmt.BindInt(1, trace_id).BindInt(2, version);
  SURFMAP_ASSIGN_OR_RETURN(bool found, stmt.Step());
  if (!found) {
    return absl::NotFoundError(
        version == 0 ? absl::StrCat("trace ", trace_id, " has no fit (or does not exist)")
                     : absl::StrCat("trace ", trace_id, " has no fit version ", version));
  }
  return ReadFit(stmt);
}

absl::StatusOr<std::vector<FitRecord>> SqliteStore::AddFits(const std::vector<TraceRefit>& fits) {
  if (fits.empty()) return std::vector<FitRecord>();
  std::set<int64_t> seen;
  for (size_t i = 0; i < fits.size(); ++i) {
    SURFMAP_RETURN_IF_ERROR(ValidateFit(fits[i].fit, absl::StrCat("fits[", i, "]")));
    if (!seen.insert(fits[i].trace_id).second) {
      return absl::InvalidArgumentError(
          absl::StrCat("fits[", i, "]: trace ", fits[i].trace_id, " appears twice in the batch"));
    }
  }
  const int64_t now = Now();
  return writer_->Run<std::vector<FitRecord>>(
      [&fits, now](SqliteConnection& db) -> absl::StatusOr<std::vector<FitRecord>> {
        int64_t highest = 0;
        for (size_t i = 0; i < fits.size(); ++i) {
          SURFMAP_ASSIGN_OR_RETURN(
              SqliteStatement stmt,
              db.Prepare("SELECT (SELECT MAX(version) FROM fits WHERE trace_id = ?1) "
                         "FROM traces WHERE id = ?1"));
          stmt.BindInt(1, fits[i].trace_id);
          SURFMAP_ASSIGN_OR_RETURN(bool found, stmt.Step());
          if (!found) {
            return absl::NotFoundError(
                absl::StrCat("fits[", i, "]: trace ", fits[i].trace_id, " does not exist"));
          }
          highest = std::max(highest, stmt.ColumnInt(0));  // NULL (no fit yet) reads as 0
        }
        const int32_t version = static_cast<int32_t>(highest + 1);
        std::vector<FitRecord> records;
        for (size_t i = 0; i < fits.size(); ++i) {
          const NewFit& f = fits[i].fit;
          absl::StatusOr<FitRecord> r = InsertFit(db, fits[i].trace_id, version, f, now);
          if (!r.ok()) return Annotate(r.status(), absl::StrCat("fits[", i, "]"));
          records.push_back(std::move(*r));
        }
        return records;
      });
}

absl::StatusOr<std::vector<FitRecord>> SqliteStore::ListFits(int64_t job_id, int32_t version) {
  // version 0: for each trace the fit with the highest version.
  static const std::string sql = absl::StrCat(
      "SELECT ", kFitColumns, " FROM fits f WHERE f.trace_id IN "
      "(SELECT id FROM traces WHERE job_id = ?1) AND "
      "(CASE WHEN ?2 = 0 THEN f.version = (SELECT MAX(version) FROM fits g "
      "WHERE g.trace_id = f.trace_id) ELSE f.version = ?2 END) ORDER BY f.trace_id");
  if (version < 0) {
    return absl::InvalidArgumentError(absl::StrCat("fit version must be >= 0, got ", version));
  }
  SURFMAP_ASSIGN_OR_RETURN(ReadConnectionPool::Loan db, readers_.Borrow());
  SURFMAP_RETURN_IF_ERROR(LoadJob(*db, job_id).status());
  SURFMAP_ASSIGN_OR_RETURN(SqliteStatement stmt, db->Prepare(sql));
  stmt.BindInt(1, job_id).BindInt(2, version);
  return CollectRows<FitRecord>(stmt, ReadFit);
}

// ---- Events ----

absl::StatusOr<std::vector<EventRecord>> SqliteStore::ListEvents(int64_t job_id, int64_t after_id,
                                                                 int limit) {
  static const std::string sql = absl::StrCat(
      "SELECT ", kEventColumns,
      " FROM events WHERE (?1 = 0 OR job_id = ?1) AND id > ?2 ORDER BY id LIMIT ?3");
  if (limit <= 0) {
    return absl::InvalidArgumentError(absl::StrCat("limit must be > 0, got ", limit));
  }
  SURFMAP_ASSIGN_OR_RETURN(ReadConnectionPool::Loan db, readers_.Borrow());
  if (job_id != 0) SURFMAP_RETURN_IF_ERROR(LoadJob(*db, job_id).status());
  SURFMAP_ASSIGN_OR_RETURN(SqliteStatement stmt, db->Prepare(sql));
  stmt.BindInt(1, job_id).BindInt(2, after_id).BindInt(3, limit);
  return CollectRows<EventRecord>(stmt, ReadEvent);
}

}  // namespace surfmap
