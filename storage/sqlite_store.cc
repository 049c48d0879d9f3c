#include "storage/sqlite_store.h"

#include <chrono>
#include <set>
#include <utility>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"
#include "server/base/status_macros.h"
#include "storage/schema.h"
#include "storage/sqlite_rows.h"
#include "storage/sqlite_writes.h"

namespace surfmap {

using sqlite::Annotate;
using sqlite::CollectRows;
using sqlite::kCommandColumns;
using sqlite::kEventColumns;
using sqlite::kFitColumns;
using sqlite::kJobColumns;
using sqlite::kObjectColumns;
using sqlite::kTraceColumns;
using sqlite::FailCommandWrite;
using sqlite::InsertCommands;
using sqlite::InsertEvents;
using sqlite::InsertFit;
using sqlite::LeaseWrite;
using sqlite::LoadCommand;
using sqlite::LoadJob;
using sqlite::ReadCommand;
using sqlite::ReadEvent;
using sqlite::ReadFit;
using sqlite::ReadJob;
using sqlite::ReadObject;
using sqlite::ReadTrace;
using sqlite::ValidateEvents;
using sqlite::ValidateFit;
using sqlite::ValidateLease;

namespace {

int64_t SystemNowUnixMs() {
  return std::chrono::duration_cast<std::chrono::milliseconds>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
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
      readers_(path_, options_.read_connections, options_.bulk_read_connections, options_.busy_timeout_ms) {}

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
  if (object.surface != "control_mesh" && object.surface != "facets") {
    return absl::InvalidArgumentError(
        absl::StrCat("surface must be \"control_mesh\" or \"facets\", got \"", object.surface, "\""));
  }
  if (object.control_vertices < 0 || object.control_faces < 0) {
    return absl::InvalidArgumentError("control_vertices and control_faces must be >= 0");
  }
  const int64_t now = Now();
  return writer_->Run<int64_t>([&object, now](SqliteConnection& db) -> absl::StatusOr<int64_t> {
    SURFMAP_ASSIGN_OR_RETURN(
        SqliteStatement stmt,
        db.Prepare("INSERT INTO objects (name, mesh_format, control_vertices, control_faces, "
                   "created_unix_ms, mesh_bytes, metadata_json, surface) VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8)"));
    stmt.BindText(1, object.name).BindText(2, object.mesh_format);
    stmt.BindInt(3, object.control_vertices).BindInt(4, object.control_faces);
    stmt.BindInt(5, now).BindBlob(6, object.mesh_bytes).BindText(7, object.metadata_json).BindText(8, object.surface);
    SURFMAP_RETURN_IF_ERROR(Annotate(stmt.Run(), "object"));
    return db.LastInsertRowId();
  });
}

absl::StatusOr<ObjectRecord> SqliteStore::GetObject(int64_t object_id, bool include_mesh) {
  static const std::string sql_with =
      absl::StrCat("SELECT ", kObjectColumns, ", mesh_bytes FROM objects WHERE id = ?1");
  static const std::string sql_without =
      absl::StrCat("SELECT ", kObjectColumns, " FROM objects WHERE id = ?1");
  SURFMAP_ASSIGN_OR_RETURN(ReadConnectionPool::Loan db,
                           readers_.Borrow(include_mesh ? ReadSize::kBulk : ReadSize::kSmall));
  SURFMAP_ASSIGN_OR_RETURN(SqliteStatement stmt,
                           db->Prepare(include_mesh ? sql_with : sql_without));
  stmt.BindInt(1, object_id);
  SURFMAP_ASSIGN_OR_RETURN(bool found, stmt.Step());
  if (!found) return absl::NotFoundError(absl::StrCat("object ", object_id, " does not exist"));
  ObjectRecord record = ReadObject(stmt);
  if (include_mesh) record.mesh_bytes = std::string(stmt.ColumnBlob(8));
  return record;
}

absl::StatusOr<std::vector<ObjectRecord>> SqliteStore::ListObjects() {
  static const std::string sql = absl::StrCat("SELECT ", kObjectColumns, " FROM objects ORDER BY id");
  SURFMAP_ASSIGN_OR_RETURN(ReadConnectionPool::Loan db, readers_.Borrow());
  SURFMAP_ASSIGN_OR_RETURN(SqliteStatement stmt, db->Prepare(sql));
  return CollectRows<ObjectRecord>(stmt, [](const SqliteStatement& s) { return ReadObject(s); });
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
                     "updated_unix_ms, metadata_json) VALUES (?1, 'running', ?2, ?3, ?3, ?4)"));
      stmt.BindInt(1, job.object_id).BindText(2, job.params_json).BindInt(3, now).BindText(4, job.metadata_json);
      SURFMAP_RETURN_IF_ERROR(Annotate(stmt.Run(), "params_json or metadata_json"));
    }
    created.job.id = db.LastInsertRowId();
    created.job.object_id = job.object_id;
    created.job.state = JobState::kRunning;
    created.job.params_json = job.params_json;
    created.job.metadata_json = job.metadata_json;
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
  return CollectRows<JobRecord>(stmt, [](const SqliteStatement& s) { return ReadJob(s); });
}

absl::StatusOr<std::vector<JobRecord>> SqliteStore::ListActiveJobs() {
  static const std::string sql =
      absl::StrCat("SELECT ", kJobColumns, " FROM jobs WHERE state IN ('running', 'paused') ORDER BY id");
  SURFMAP_ASSIGN_OR_RETURN(ReadConnectionPool::Loan db, readers_.Borrow());
  SURFMAP_ASSIGN_OR_RETURN(SqliteStatement stmt, db->Prepare(sql));
  return CollectRows<JobRecord>(stmt, [](const SqliteStatement& s) { return ReadJob(s); });
}

void SqliteStore::UpdateJobStateAsync(JobStateChange change, JobCallback done) {
  if (absl::Status s = sqlite::ValidateEvents(change.events); !s.ok()) {
    done(std::move(s));
    return;
  }
  const int64_t now = Now();
  writer_->SubmitForResult<JobRecord>(
      [change = std::move(change), now](SqliteConnection& db) -> absl::StatusOr<JobRecord> {
        SURFMAP_ASSIGN_OR_RETURN(JobRecord job, LoadJob(db, change.job_id));
        SURFMAP_RETURN_IF_ERROR(sqlite::SetJobState(db, job, change.new_state, now));
        SURFMAP_RETURN_IF_ERROR(sqlite::InsertEvents(db, job.id, change.events, now));
        job.state = change.new_state;
        job.updated_unix_ms = now;
        return job;
      },
      std::move(done));
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
  return CollectRows<CommandRecord>(stmt, [](const SqliteStatement& s) { return ReadCommand(s); });
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
  if (request.samples.empty() == request.encoded_samples.empty()) {
    done(absl::InvalidArgumentError(absl::StrCat(
        "trace for command ", request.command_id,
        request.samples.empty() ? " has no samples" : " gives both samples and encoded samples")));
    return;
  }
  if (request.encoded_samples.size() % kEncodedSampleBytes != 0) {
    done(absl::InvalidArgumentError(absl::StrCat("trace for command ", request.command_id, ": encoded samples of ",
                                                 request.encoded_samples.size(), " bytes are not whole samples")));
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
  if (request.import.has_value()) {
    if (absl::Status s = sqlite::ValidateImport(request); !s.ok()) {
      done(std::move(s));
      return;
    }
  }
  if (absl::Status s = sqlite::ValidateFrame(request.frame, request.registration_id); !s.ok()) {
    done(std::move(s));
    return;
  }
  // Encode here, on the caller's thread: the writer thread is the bottleneck.
  auto encoded = std::make_shared<sqlite::EncodedTrace>();
  if (request.encoded_samples.empty()) {
    encoded->n_samples = static_cast<int64_t>(request.samples.size());
    encoded->blob = EncodeSamples(request.samples);
  } else {
    encoded->n_samples = static_cast<int64_t>(request.encoded_samples.size() / kEncodedSampleBytes);
    encoded->blob = std::move(request.encoded_samples);
  }
  request.samples = {};
  request.encoded_samples = {};
  encoded->request = std::move(request);
  const int64_t now = Now();
  writer_->SubmitForResult<AcceptTraceResult>(
      [encoded, now](SqliteConnection& db) -> absl::StatusOr<AcceptTraceResult> {
        absl::StatusOr<AcceptTraceResult> result = sqlite::AcceptTraceWrite(db, *encoded, now);
        if (!result.ok()) {
          return Annotate(result.status(), absl::StrCat("AcceptTrace(command ", encoded->request.command_id, ")"));
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
  SURFMAP_ASSIGN_OR_RETURN(ReadConnectionPool::Loan db,
                           readers_.Borrow(include_samples ? ReadSize::kBulk : ReadSize::kSmall));
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
  SURFMAP_ASSIGN_OR_RETURN(ReadConnectionPool::Loan db, readers_.Borrow(ReadSize::kBulk));
  SURFMAP_RETURN_IF_ERROR(LoadJob(*db, job_id).status());
  SURFMAP_ASSIGN_OR_RETURN(SqliteStatement stmt,
                           db->Prepare(include_samples ? sql_with : sql_without));
  stmt.BindInt(1, job_id);
  return CollectRows<TraceRecord>(
      stmt, [include_samples](const SqliteStatement& s) { return ReadTrace(s, include_samples); });
}

absl::StatusOr<std::vector<TraceRecord>> SqliteStore::ListTracesPage(int64_t job_id, int64_t after_trace_id,
                                                                     int limit, bool include_samples) {
  static const std::string sql_with = absl::StrCat(
      "SELECT ", kTraceColumns, ", samples FROM traces WHERE job_id = ?1 AND id > ?2 ORDER BY id LIMIT ?3");
  static const std::string sql_without = absl::StrCat(
      "SELECT ", kTraceColumns, " FROM traces WHERE job_id = ?1 AND id > ?2 ORDER BY id LIMIT ?3");
  if (limit <= 0) return absl::InvalidArgumentError(absl::StrCat("limit must be > 0, got ", limit));
  SURFMAP_ASSIGN_OR_RETURN(ReadConnectionPool::Loan db,
                           readers_.Borrow(include_samples ? ReadSize::kBulk : ReadSize::kSmall));
  SURFMAP_RETURN_IF_ERROR(LoadJob(*db, job_id).status());
  SURFMAP_ASSIGN_OR_RETURN(SqliteStatement stmt, db->Prepare(include_samples ? sql_with : sql_without));
  stmt.BindInt(1, job_id).BindInt(2, after_trace_id).BindInt(3, limit);
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
  return CollectRows<FitRecord>(stmt, [](const SqliteStatement& s) { return ReadFit(s); });
}

// ---- Samples ----

namespace {

// SELECT list of a sample row: the trace, its command, its fit (and the
// trace's samples last, when wanted). One statement is one snapshot.
std::string SampleColumns(bool with_samples) {
  std::string trace = absl::StrCat(kTraceColumns);
  std::string command = absl::StrCat(kCommandColumns);
  std::string fit = absl::StrCat(kFitColumns);
  auto prefix = [](const std::string& columns, const char* table) {
    std::string out;
    size_t start = 0;
    while (start <= columns.size()) {
      size_t comma = columns.find(',', start);
      std::string name = columns.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
      while (!name.empty() && name.front() == ' ') name.erase(name.begin());
      absl::StrAppend(&out, out.empty() ? "" : ", ", table, ".", name);
      if (comma == std::string::npos) break;
      start = comma + 1;
    }
    return out;
  };
  return absl::StrCat(prefix(trace, "t"), ", ", prefix(command, "c"), ", ", prefix(fit, "f"),
                      with_samples ? ", t.samples" : "");
}

absl::StatusOr<SampleRecord> ReadSampleRow(const SqliteStatement& s, bool with_samples) {
  constexpr int kCommandAt = sqlite::kTraceColumnCount;
  constexpr int kFitAt = kCommandAt + sqlite::kCommandColumnCount;
  constexpr int kSamplesAt = kFitAt + sqlite::kFitColumnCount;
  SampleRecord r;
  SURFMAP_ASSIGN_OR_RETURN(r.trace, ReadTrace(s, with_samples, 0, kSamplesAt));
  absl::StatusOr<CommandRecord> command = ReadCommand(s, kCommandAt);
  if (!command.ok()) {
    return absl::DataLossError(absl::StrCat("command ", r.trace.command_id, " of trace ", r.trace.id,
                                            " cannot be read: ", command.status().message()));
  }
  r.command = std::move(*command);
  r.fit = ReadFit(s, kFitAt);
  return r;
}

}  // namespace

absl::StatusOr<SampleRecord> SqliteStore::ReadSample(int64_t trace_id, int32_t fit_version, bool include_samples) {
  static const std::string from =
      " FROM traces t JOIN commands c ON c.id = t.command_id JOIN fits f ON f.trace_id = t.id "
      "WHERE t.id = ?1 AND (?2 = 0 OR f.version = ?2) ORDER BY f.version DESC LIMIT 1";
  static const std::string sql_with = absl::StrCat("SELECT ", SampleColumns(true), from);
  static const std::string sql_without = absl::StrCat("SELECT ", SampleColumns(false), from);
  if (fit_version < 0) {
    return absl::InvalidArgumentError(absl::StrCat("fit version must be >= 0, got ", fit_version));
  }
  SURFMAP_ASSIGN_OR_RETURN(ReadConnectionPool::Loan db,
                           readers_.Borrow(include_samples ? ReadSize::kBulk : ReadSize::kSmall));
  SURFMAP_ASSIGN_OR_RETURN(SqliteStatement stmt, db->Prepare(include_samples ? sql_with : sql_without));
  stmt.BindInt(1, trace_id).BindInt(2, fit_version);
  SURFMAP_ASSIGN_OR_RETURN(bool found, stmt.Step());
  if (found) return ReadSampleRow(stmt, include_samples);
  // Say which part is missing.
  SURFMAP_ASSIGN_OR_RETURN(SqliteStatement exists, db->Prepare("SELECT 1 FROM traces WHERE id = ?1"));
  exists.BindInt(1, trace_id);
  SURFMAP_ASSIGN_OR_RETURN(bool trace_exists, exists.Step());
  if (!trace_exists) return absl::NotFoundError(absl::StrCat("trace ", trace_id, " does not exist"));
  return absl::NotFoundError(fit_version == 0 ? absl::StrCat("trace ", trace_id, " has no fit")
                                              : absl::StrCat("trace ", trace_id, " has no fit version ", fit_version));
}

absl::StatusOr<std::vector<SampleRecord>> SqliteStore::ReadJobSamples(int64_t job_id, int32_t fit_version) {
  // version 0: for each trace the fit with the highest version.
  static const std::string sql = absl::StrCat(
      "SELECT ", SampleColumns(false),
      " FROM traces t JOIN commands c ON c.id = t.command_id JOIN fits f ON f.trace_id = t.id "
      "WHERE t.job_id = ?1 AND (CASE WHEN ?2 = 0 THEN f.version = (SELECT MAX(version) FROM fits g "
      "WHERE g.trace_id = t.id) ELSE f.version = ?2 END) ORDER BY t.id");
  if (fit_version < 0) {
    return absl::InvalidArgumentError(absl::StrCat("fit version must be >= 0, got ", fit_version));
  }
  SURFMAP_ASSIGN_OR_RETURN(ReadConnectionPool::Loan db, readers_.Borrow(ReadSize::kBulk));
  // One read transaction: the job check and the rows see the same commit.
  SURFMAP_RETURN_IF_ERROR(db->Exec("BEGIN"));
  absl::StatusOr<std::vector<SampleRecord>> rows = [&]() -> absl::StatusOr<std::vector<SampleRecord>> {
    SURFMAP_RETURN_IF_ERROR(LoadJob(*db, job_id).status());
    SURFMAP_ASSIGN_OR_RETURN(SqliteStatement stmt, db->Prepare(sql));
    stmt.BindInt(1, job_id).BindInt(2, fit_version);
    return CollectRows<SampleRecord>(stmt, [](const SqliteStatement& s) { return ReadSampleRow(s, false); });
  }();
  db->Exec("COMMIT").IgnoreError();  // a read transaction: nothing to lose
  return rows;
}

// ---- Rejected traces ----

namespace {

constexpr char kRejectedColumns[] =
    "id, command_id, job_id, rig_id, check_name, message, n_samples, sample_encoding, received_unix_ms, "
    "import_sha256, frame, registration_id";

absl::StatusOr<RejectedTraceRecord> ReadRejected(const SqliteStatement& s, bool with_samples) {
  RejectedTraceRecord r;
  r.id = s.ColumnInt(0);
  r.command_id = s.ColumnInt(1);
  r.job_id = s.ColumnInt(2);
  r.rig_id = s.ColumnText(3);
  r.check_name = s.ColumnText(4);
  r.message = s.ColumnText(5);
  r.n_samples = s.ColumnInt(6);
  r.received_unix_ms = s.ColumnInt(8);
  r.import_sha256 = s.ColumnText(9);  // "" for NULL
  r.frame = s.ColumnText(10);
  r.registration_id = s.ColumnInt(11);
  if (with_samples) {
    if (s.ColumnInt(7) != kSampleEncodingPackedLE) {
      return absl::DataLossError(absl::StrCat("rejected trace ", r.id, " has unknown sample encoding"));
    }
    SURFMAP_ASSIGN_OR_RETURN(r.samples, DecodeSamples(s.ColumnBlob(12)));
  }
  return r;
}

}  // namespace

void SqliteStore::RecordRejectedTraceAsync(NewRejectedTrace trace, RejectedCallback done) {
  if (trace.encoded_samples.empty() || trace.encoded_samples.size() % kEncodedSampleBytes != 0) {
    done(absl::InvalidArgumentError("rejected trace: encoded samples are empty or not whole samples"));
    return;
  }
  if (absl::Status s = ValidateEvents(trace.events); !s.ok()) {
    done(std::move(s));
    return;
  }
  if (trace.implied_command.has_value() != (trace.command_id == 0)) {
    done(absl::InvalidArgumentError("rejected trace: give a command_id or an implied command (an import), not both"));
    return;
  }
  if (absl::Status s = sqlite::ValidateFrame(trace.frame, trace.registration_id); !s.ok()) {
    done(std::move(s));
    return;
  }
  if (trace.implied_command.has_value()) {
    if (absl::Status s = sqlite::ValidateSha256(trace.import_sha256, "rejected trace: import_sha256"); !s.ok()) {
      done(std::move(s));
      return;
    }
  } else if (!trace.import_sha256.empty()) {
    done(absl::InvalidArgumentError("rejected trace: import_sha256 is for a refused import (implied command) only"));
    return;
  }
  auto shared = std::make_shared<NewRejectedTrace>(std::move(trace));
  const int64_t now = Now();
  writer_->SubmitForResult<int64_t>(
      [shared, now](SqliteConnection& db) -> absl::StatusOr<int64_t> {
        if (shared->implied_command.has_value()) {
          // A refused import: its implied command, failed, names the source.
          // The job must take imports, as for a stored one (checked first).
          SURFMAP_ASSIGN_OR_RETURN(JobRecord job, LoadJob(db, shared->job_id));
          SURFMAP_RETURN_IF_ERROR(sqlite::CheckTakesImports(job));
          // The same file refused before: its rejected trace, nothing written
          // (a refused file imported again and again does not grow the file).
          SURFMAP_ASSIGN_OR_RETURN(
              SqliteStatement same,
              db.Prepare("SELECT id FROM rejected_traces WHERE job_id = ?1 AND import_sha256 = ?2"));
          same.BindInt(1, shared->job_id).BindText(2, shared->import_sha256);
          SURFMAP_ASSIGN_OR_RETURN(bool stored, same.Step());
          if (stored) return same.ColumnInt(0);
          SURFMAP_ASSIGN_OR_RETURN(shared->command_id,
                                   sqlite::InsertAnsweredCommand(db, shared->job_id, *shared->implied_command,
                                                                 "failed", shared->rig_id, now, "implied_command"));
        } else {
          SURFMAP_ASSIGN_OR_RETURN(CommandRecord command, LoadCommand(db, shared->command_id));
          if (command.job_id != shared->job_id) {
            return absl::InvalidArgumentError(absl::StrCat("command ", command.id, " belongs to job ", command.job_id));
          }
        }
        SURFMAP_RETURN_IF_ERROR(InsertEvents(db, shared->job_id, shared->events, now));
        SURFMAP_ASSIGN_OR_RETURN(SqliteStatement count,
                                 db.Prepare("SELECT COUNT(*) FROM rejected_traces WHERE command_id = ?1"));
        count.BindInt(1, shared->command_id);
        SURFMAP_ASSIGN_OR_RETURN(bool row, count.Step());
        if (row && count.ColumnInt(0) >= Store::kMaxRejectedPerCommand) return int64_t{0};
        SURFMAP_ASSIGN_OR_RETURN(
            SqliteStatement stmt,
            db.Prepare("INSERT INTO rejected_traces (command_id, job_id, rig_id, check_name, message, n_samples, "
                       "sample_encoding, received_unix_ms, samples, import_sha256, frame, registration_id) "
                       "VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8, ?9, ?10, ?11, ?12)"));
        stmt.BindInt(1, shared->command_id).BindInt(2, shared->job_id).BindText(3, shared->rig_id);
        stmt.BindText(4, shared->check_name).BindText(5, shared->message);
        stmt.BindInt(6, static_cast<int64_t>(shared->encoded_samples.size() / kEncodedSampleBytes));
        stmt.BindInt(7, kSampleEncodingPackedLE).BindInt(8, now).BindBlob(9, shared->encoded_samples);
        if (shared->import_sha256.empty()) {
          stmt.BindNull(10);
        } else {
          stmt.BindText(10, shared->import_sha256);
        }
        stmt.BindText(11, shared->frame.empty() ? std::string("object") : shared->frame);
        stmt.BindInt(12, shared->registration_id);
        SURFMAP_RETURN_IF_ERROR(Annotate(stmt.Run(), "storing the rejected trace"));
        return db.LastInsertRowId();
      },
      std::move(done));
}

absl::StatusOr<int64_t> SqliteStore::FindImportedTrace(int64_t job_id, const std::string& sha256) {
  SURFMAP_ASSIGN_OR_RETURN(ReadConnectionPool::Loan db, readers_.Borrow());
  SURFMAP_ASSIGN_OR_RETURN(SqliteStatement stmt,
                           db->Prepare("SELECT id FROM traces WHERE job_id = ?1 AND import_sha256 = ?2"));
  stmt.BindInt(1, job_id).BindText(2, sha256);
  SURFMAP_ASSIGN_OR_RETURN(bool found, stmt.Step());
  return found ? stmt.ColumnInt(0) : int64_t{0};
}

absl::StatusOr<std::vector<RejectedTraceRecord>> SqliteStore::ListRejectedTraces(int64_t job_id) {
  static const std::string sql =
      absl::StrCat("SELECT ", kRejectedColumns, " FROM rejected_traces WHERE job_id = ?1 ORDER BY id");
  SURFMAP_ASSIGN_OR_RETURN(ReadConnectionPool::Loan db, readers_.Borrow());
  SURFMAP_RETURN_IF_ERROR(LoadJob(*db, job_id).status());
  SURFMAP_ASSIGN_OR_RETURN(SqliteStatement stmt, db->Prepare(sql));
  stmt.BindInt(1, job_id);
  return CollectRows<RejectedTraceRecord>(stmt, [](const SqliteStatement& s) { return ReadRejected(s, false); });
}

absl::StatusOr<RejectedTraceRecord> SqliteStore::GetRejectedTrace(int64_t id) {
  static const std::string sql =
      absl::StrCat("SELECT ", kRejectedColumns, ", samples FROM rejected_traces WHERE id = ?1");
  SURFMAP_ASSIGN_OR_RETURN(ReadConnectionPool::Loan db, readers_.Borrow(ReadSize::kBulk));
  SURFMAP_ASSIGN_OR_RETURN(SqliteStatement stmt, db->Prepare(sql));
  stmt.BindInt(1, id);
  SURFMAP_ASSIGN_OR_RETURN(bool found, stmt.Step());
  if (!found) return absl::NotFoundError(absl::StrCat("rejected trace ", id, " does not exist"));
  return ReadRejected(stmt, true);
}

// ---- Ordering ----

void SqliteStore::SyncAsync(std::function<void(absl::Status)> done) {
  writer_->Submit([](SqliteConnection&) { return absl::OkStatus(); }, std::move(done));
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

absl::StatusOr<std::vector<EventRecord>> SqliteStore::ListEventsNewestFirst(int64_t job_id, int64_t before_id,
                                                                            int limit) {
  static const std::string sql = absl::StrCat(
      "SELECT ", kEventColumns,
      " FROM events WHERE (?1 = 0 OR job_id = ?1) AND (?2 = 0 OR id < ?2) ORDER BY id DESC LIMIT ?3");
  if (limit <= 0) {
    return absl::InvalidArgumentError(absl::StrCat("limit must be > 0, got ", limit));
  }
  SURFMAP_ASSIGN_OR_RETURN(ReadConnectionPool::Loan db, readers_.Borrow());
  if (job_id != 0) SURFMAP_RETURN_IF_ERROR(LoadJob(*db, job_id).status());
  SURFMAP_ASSIGN_OR_RETURN(SqliteStatement stmt, db->Prepare(sql));
  stmt.BindInt(1, job_id).BindInt(2, before_id).BindInt(3, limit);
  return CollectRows<EventRecord>(stmt, ReadEvent);
}

}  // namespace surfmap