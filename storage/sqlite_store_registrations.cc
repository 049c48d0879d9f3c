// SqliteStore: rig registrations and the frames of stored traces (schema
// version 5). A registration is never updated: a new one for the same
// (object, rig) is the next version, so a trace converted with an older one
// can always be read back with it.
#include "absl/strings/str_cat.h"
#include "server/base/status_macros.h"
#include "storage/sqlite_rows.h"
#include "storage/sqlite_store.h"
#include "storage/sqlite_writes.h"

namespace surfmap {
namespace {

constexpr char kRegistrationColumns[] =
    "id, object_id, rig_name, version, created_unix_ms, registration_json";

RigRegistrationRecord ReadRegistration(const SqliteStatement& s) {
  RigRegistrationRecord r;
  r.id = s.ColumnInt(0);
  r.object_id = s.ColumnInt(1);
  r.rig_name = std::string(s.ColumnText(2));
  r.version = static_cast<int32_t>(s.ColumnInt(3));
  r.created_unix_ms = s.ColumnInt(4);
  r.registration_json = std::string(s.ColumnText(5));
  return r;
}

absl::StatusOr<RigRegistrationRecord> LoadRegistration(SqliteConnection& db, int64_t id) {
  static const std::string sql =
      absl::StrCat("SELECT ", kRegistrationColumns, " FROM rig_registrations WHERE id = ?1");
  SURFMAP_ASSIGN_OR_RETURN(SqliteStatement stmt, db.Prepare(sql));
  stmt.BindInt(1, id);
  SURFMAP_ASSIGN_OR_RETURN(bool found, stmt.Step());
  if (!found) return absl::NotFoundError(absl::StrCat("rig registration ", id, " does not exist"));
  return ReadRegistration(stmt);
}

}  // namespace

absl::StatusOr<RigRegistrationRecord> SqliteStore::AddRigRegistration(const NewRigRegistration& registration) {
  if (registration.rig_name.empty()) return absl::InvalidArgumentError("rig_name is empty");
  if (registration.registration_json.empty()) return absl::InvalidArgumentError("registration_json is empty");
  const int64_t now = Now();
  return writer_->Run<RigRegistrationRecord>(
      [&registration, now](SqliteConnection& db) -> absl::StatusOr<RigRegistrationRecord> {
        SURFMAP_ASSIGN_OR_RETURN(SqliteStatement object, db.Prepare("SELECT 1 FROM objects WHERE id = ?1"));
        object.BindInt(1, registration.object_id);
        SURFMAP_ASSIGN_OR_RETURN(bool exists, object.Step());
        if (!exists) return absl::NotFoundError(absl::StrCat("object ", registration.object_id, " does not exist"));
        SURFMAP_ASSIGN_OR_RETURN(
            SqliteStatement stmt,
            db.Prepare("INSERT INTO rig_registrations (object_id, rig_name, version, created_unix_ms, "
                       "registration_json) VALUES (?1, ?2, (SELECT COALESCE(MAX(version), 0) + 1 FROM "
                       "rig_registrations WHERE object_id = ?1 AND rig_name = ?2), ?3, ?4)"));
        stmt.BindInt(1, registration.object_id).BindText(2, registration.rig_name);
        stmt.BindInt(3, now).BindText(4, registration.registration_json);
        SURFMAP_RETURN_IF_ERROR(sqlite::Annotate(stmt.Run(), "storing the rig registration"));
        return LoadRegistration(db, db.LastInsertRowId());
      });
}

absl::StatusOr<RigRegistrationRecord> SqliteStore::GetRigRegistration(int64_t registration_id) {
  SURFMAP_ASSIGN_OR_RETURN(ReadConnectionPool::Loan db, readers_.Borrow());
  return LoadRegistration(*db, registration_id);
}

absl::StatusOr<std::vector<RigRegistrationRecord>> SqliteStore::ListRigRegistrations(int64_t object_id) {
  static const std::string all = absl::StrCat("SELECT ", kRegistrationColumns, " FROM rig_registrations ORDER BY id");
  static const std::string one =
      absl::StrCat("SELECT ", kRegistrationColumns, " FROM rig_registrations WHERE object_id = ?1 ORDER BY id");
  SURFMAP_ASSIGN_OR_RETURN(ReadConnectionPool::Loan db, readers_.Borrow());
  SURFMAP_ASSIGN_OR_RETURN(SqliteStatement stmt, db->Prepare(object_id == 0 ? all : one));
  if (object_id != 0) stmt.BindInt(1, object_id);
  return sqlite::CollectRows<RigRegistrationRecord>(stmt,
                                                    [](const SqliteStatement& s) { return ReadRegistration(s); });
}

absl::StatusOr<TraceFrameRecord> SqliteStore::GetTraceFrame(int64_t trace_id) {
  // One query: the trace's row says it exists, the joined frame row (none for
  // a trace sent in the object's frame) what it was sent in.
  SURFMAP_ASSIGN_OR_RETURN(ReadConnectionPool::Loan db, readers_.Borrow());
  SURFMAP_ASSIGN_OR_RETURN(SqliteStatement stmt,
                           db->Prepare("SELECT f.frame, f.registration_id FROM traces t "
                                       "LEFT JOIN trace_frames f ON f.trace_id = t.id WHERE t.id = ?1"));
  stmt.BindInt(1, trace_id);
  SURFMAP_ASSIGN_OR_RETURN(bool found, stmt.Step());
  if (!found) return absl::NotFoundError(absl::StrCat("trace ", trace_id, " does not exist"));
  TraceFrameRecord record;
  if (!stmt.ColumnIsNull(0)) {
    record.frame = std::string(stmt.ColumnText(0));
    record.registration_id = stmt.ColumnInt(1);
  }
  return record;
}

}  // namespace surfmap
