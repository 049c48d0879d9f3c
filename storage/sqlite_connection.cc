#include "storage/sqlite_connection.h"

#include <sqlite3.h>

#include <cmath>

#include "absl/strings/str_cat.h"

namespace surfmap {

absl::Status SqliteError(int code, std::string_view context, std::string_view sqlite_message) {
  std::string message = absl::StrCat(std::string(context), ": ", std::string(sqlite_message));
  switch (code & 0xff) {
    case SQLITE_BUSY:
    case SQLITE_LOCKED:
    case SQLITE_IOERR:
    case SQLITE_FULL:
    case SQLITE_CANTOPEN:
    case SQLITE_PROTOCOL:
      return absl::UnavailableError(message);
    default:
      break;
  }
  if (code == SQLITE_CONSTRAINT_CHECK || code == SQLITE_CONSTRAINT_NOTNULL) {
    return absl::InvalidArgumentError(message);
  }
  return absl::InternalError(message);
}

// ---- SqliteStatement ----

SqliteStatement::SqliteStatement(SqliteConnection* connection, sqlite3_stmt* stmt)
    : connection_(connection), stmt_(stmt) {}

SqliteStatement::SqliteStatement(SqliteStatement&& other) noexcept
    : connection_(other.connection_), stmt_(other.stmt_), bind_status_(other.bind_status_) {
  other.stmt_ = nullptr;
}

SqliteStatement::~SqliteStatement() {
  if (stmt_ != nullptr) {
    sqlite3_reset(stmt_);
    sqlite3_clear_bindings(stmt_);
  }
}

void SqliteStatement::NoteBind(int rc, int index) {
  if (rc != SQLITE_OK && bind_status_.ok()) {
    bind_status_ = connection_->LastError(rc, absl::StrCat("binding parameter ", index, " of '",
                                                           sqlite3_sql(stmt_), "'"));
  }
}

SqliteStatement& SqliteStatement::BindInt(int index, int64_t value) {
  NoteBind(sqlite3_bind_int64(stmt_, index, value), index);
  return *this;
}

SqliteStatement& SqliteStatement::BindDouble(int index, double value) {
  NoteBind(sqlite3_bind_double(stmt_, index, value), index);
  return *this;
}

SqliteStatement& SqliteStatement::BindOptionalDouble(int index, const std::optional<double>& value) {
  // SQLite stores NaN as NULL anyway; do it explicitly so reads agree.
  if (!value.has_value() || std::isnan(*value)) return BindNull(index);
  return BindDouble(index, *value);
}

SqliteStatement& SqliteStatement::BindText(int index, std::string_view value) {
  NoteBind(sqlite3_bind_text64(stmt_, index, value.data(), value.size(), SQLITE_TRANSIENT,
                               SQLITE_UTF8),
           index);
  return *this;
}

SqliteStatement& SqliteStatement::BindBlob(int index, std::string_view value) {
  // SQLITE_STATIC: callers keep the bytes alive until the statement is done,
  // which saves copying large sample blobs.
  NoteBind(sqlite3_bind_blob64(stmt_, index, value.empty() ? "" : value.data(), value.size(),
                               SQLITE_STATIC),
           index);
  return *this;
}

SqliteStatement& SqliteStatement::BindNull(int index) {
  NoteBind(sqlite3_bind_null(stmt_, index), index);
  return *this;
}

absl::StatusOr<bool> SqliteStatement::Step() {
  if (!bind_status_.ok()) return bind_status_;
  int rc = sqlite3_step(stmt_);
  if (rc == SQLITE_ROW) return true;
  if (rc == SQLITE_DONE) return false;
  return connection_->LastError(rc, absl::StrCat("executing '", sqlite3_sql(stmt_), "'"));
}

absl::Status SqliteStatement::Run() {
  while (true) {
    absl::StatusOr<bool> row = Step();
    if (!row.ok()) return row.status();
    if (!*row) return absl::OkStatus();
  }
}

int64_t SqliteStatement::ColumnInt(int index) const { return sqlite3_column_int64(stmt_, index); }

double SqliteStatement::ColumnDouble(int index) const {
  return sqlite3_column_double(stmt_, index);
}

std::optional<double> SqliteStatement::ColumnOptionalDouble(int index) const {
  if (ColumnIsNull(index)) return std::nullopt;
  return sqlite3_column_double(stmt_, index);
}

std::string SqliteStatement::ColumnText(int index) const {
  const unsigned char* text = sqlite3_column_text(stmt_, index);
  if (text == nullptr) return std::string();
  return std::string(reinterpret_cast<const char*>(text),
                     static_cast<size_t>(sqlite3_column_bytes(stmt_, index)));
}

std::string_view SqliteStatement::ColumnBlob(int index) const {
  const void* data = sqlite3_column_blob(stmt_, index);
  if (data == nullptr) return std::string_view();
  return std::string_view(static_cast<const char*>(data),
                          static_cast<size_t>(sqlite3_column_bytes(stmt_, index)));
}

bool SqliteStatement::ColumnIsNull(int index) const {
  return sqlite3_column_type(stmt_, index) == SQLITE_NULL;
}

// ---- SqliteConnection ----

absl::StatusOr<std::unique_ptr<SqliteConnection>> SqliteConnection::Open(
    const std::string& path, const SqliteOpenOptions& options) {
  sqlite3* db = nullptr;
  int flags = SQLITE_OPEN_READWRITE | SQLITE_OPEN_NOMUTEX;
  if (options.create) flags |= SQLITE_OPEN_CREATE;
  int rc = sqlite3_open_v2(path.c_str(), &db, flags, nullptr);
  if (rc != SQLITE_OK) {
    absl::Status status = SqliteError(rc, absl::StrCat("opening database '", path, "'"),
                                      db != nullptr ? sqlite3_errmsg(db) : sqlite3_errstr(rc));
    sqlite3_close_v2(db);
    return status;
  }
  sqlite3_extended_result_codes(db, 1);
  std::unique_ptr<SqliteConnection> connection(new SqliteConnection(db, path));
  sqlite3_busy_timeout(db, options.busy_timeout_ms);
  // Must precede the switch to WAL; ignored by SQLite for an existing file.
  if (absl::Status s = connection->Exec(absl::StrCat("PRAGMA page_size = ", options.page_size));
      !s.ok()) {
    return s;
  }
  // journal_mode=WAL is persistent in the file; setting it on every
  // connection is harmless and makes a fresh file WAL before the first write.
  {
    absl::StatusOr<SqliteStatement> wal = connection->Prepare("PRAGMA journal_mode=WAL");
    if (!wal.ok()) return wal.status();
    absl::StatusOr<bool> row = wal->Step();
    if (!row.ok()) return row.status();
    if (!*row || wal->ColumnText(0) != "wal") {
      return absl::UnavailableError(
          absl::StrCat("database '", path, "': cannot switch to WAL journal mode (got '",
                       *row ? wal->ColumnText(0) : std::string(), "')"));
    }
  }
  std::string pragmas =
      "PRAGMA synchronous=FULL; PRAGMA foreign_keys=ON; PRAGMA temp_store=MEMORY;";
  if (options.read_only) pragmas += " PRAGMA query_only=ON;";
  if (absl::Status s = connection->Exec(pragmas); !s.ok()) return s;
  return connection;
}

SqliteConnection::~SqliteConnection() {
  for (auto& [sql, stmt] : statements_) sqlite3_finalize(stmt);
  sqlite3_close_v2(db_);
}

absl::Status SqliteConnection::Exec(std::string_view sql) {
  std::string text(sql);
  char* error = nullptr;
  int rc = sqlite3_exec(db_, text.c_str(), nullptr, nullptr, &error);
  if (rc == SQLITE_OK) return absl::OkStatus();
  absl::Status status = SqliteError(rc, absl::StrCat("executing '", std::string(sql.substr(0, 80)), "'"),
                                    error != nullptr ? error : sqlite3_errmsg(db_));
  sqlite3_free(error);
  return status;
}

absl::StatusOr<SqliteStatement> SqliteConnection::Prepare(std::string_view sql) {
  std::string key(sql);
  auto it = statements_.find(key);
  if (it == statements_.end()) {
    sqlite3_stmt* stmt = nullptr;
    int rc = sqlite3_prepare_v3(db_, key.data(), static_cast<int>(key.size()),
                                SQLITE_PREPARE_PERSISTENT, &stmt, nullptr);
    if (rc != SQLITE_OK) return LastError(rc, absl::StrCat("preparing '", std::string(sql), "'"));
    it = statements_.emplace(std::move(key), stmt).first;
  }
  return SqliteStatement(this, it->second);
}

absl::StatusOr<int64_t> SqliteConnection::QueryInt(std::string_view sql) {
  absl::StatusOr<SqliteStatement> stmt = Prepare(sql);
  if (!stmt.ok()) return stmt.status();
  absl::StatusOr<bool> row = stmt->Step();
  if (!row.ok()) return row.status();
  if (!*row) return absl::InternalError(absl::StrCat("'", std::string(sql), "' returned no row"));
  return stmt->ColumnInt(0);
}

int64_t SqliteConnection::LastInsertRowId() const { return sqlite3_last_insert_rowid(db_); }

int SqliteConnection::Changes() const { return sqlite3_changes(db_); }

absl::Status SqliteConnection::LastError(int code, std::string_view context) const {
  return SqliteError(code, context, sqlite3_errmsg(db_));
}

}  // namespace surfmap
