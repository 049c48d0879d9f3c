// A thin RAII layer over one sqlite3 connection: opening with the store's
// pragmas, cached prepared statements, and SQLite errors as absl::Status.
// A connection is used by one thread at a time (SQLITE_OPEN_NOMUTEX).
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <unordered_map>

#include "absl/status/status.h"
#include "absl/status/statusor.h"

struct sqlite3;
struct sqlite3_stmt;

namespace surfmap {

// Maps a SQLite result code to a status code by meaning: busy/locked/I/O/full/
// cannot-open -> Unavailable, CHECK/NOT NULL constraint -> InvalidArgument,
// anything else -> Internal. The message is "<context>: <sqlite3 message>".
absl::Status SqliteError(int code, std::string_view context, std::string_view sqlite_message);

class SqliteConnection;

// A prepared statement borrowed from a connection's cache; reset and unbound
// when it goes out of scope. Bind indexes start at 1 as in SQLite. Bind errors
// are remembered and returned by the next Step/Run.
class SqliteStatement {
 public:
  SqliteStatement(SqliteStatement&& other) noexcept;
  SqliteStatement& operator=(SqliteStatement&&) = delete;
  ~SqliteStatement();

  SqliteStatement& BindInt(int index, int64_t value);
  SqliteStatement& BindDouble(int index, double value);
  SqliteStatement& BindOptionalDouble(int index, const std::optional<double>& value);
  SqliteStatement& BindText(int index, std::string_view value);
  SqliteStatement& BindBlob(int index, std::string_view value);
  SqliteStatement& BindNull(int index);

  // true: a row is available; false: done.
  absl::StatusOr<bool> Step();
  // Steps to completion (for statements that return no rows).
  absl::Status Run();

  int64_t ColumnInt(int index) const;
  double ColumnDouble(int index) const;
  std::optional<double> ColumnOptionalDouble(int index) const;  // NULL -> nullopt
  std::string ColumnText(int index) const;
  std::string_view ColumnBlob(int index) const;  // valid until the next Step
  bool ColumnIsNull(int index) const;

 private:
  friend class SqliteConnection;
  SqliteStatement(SqliteConnection* connection, sqlite3_stmt* stmt);
  void NoteBind(int rc, int index);

  SqliteConnection* connection_;
  sqlite3_stmt* stmt_;
  absl::Status bind_status_;
};

struct SqliteOpenOptions {
  bool create = true;          // create the file if missing
  bool read_only = false;      // PRAGMA query_only: this connection never writes
  int busy_timeout_ms = 5000;  // wait this long for another process's lock
  // Page size of a NEW database file (no effect on an existing one). 16 KiB
  // rather than SQLite's 4 KiB: a 1,000-sample trace (57 KB) then spans 4
  // pages instead of 15, i.e. fewer WAL frames per commit (measured ~1.4x more
  // traces/s per fsync'd batch on the project VM).
  int page_size = 16384;
};

class SqliteConnection {
 public:
  // Opens path and applies the store's connection settings: WAL journal,
  // synchronous=FULL (in WAL mode NORMAL may lose the last commits on power
  // loss), foreign_keys=ON, busy_timeout. Unavailable if the file cannot be
  // opened (the message names the path).
  static absl::StatusOr<std::unique_ptr<SqliteConnection>> Open(const std::string& path,
                                                                const SqliteOpenOptions& options);
  ~SqliteConnection();
  SqliteConnection(const SqliteConnection&) = delete;
  SqliteConnection& operator=(const SqliteConnection&) = delete;

  // Runs one or more statements that return no rows (schema, BEGIN, pragmas).
  absl::Status Exec(std::string_view sql);
  // A cached prepared statement for sql (one statement). A statement must not
  // be prepared again while a borrowed copy of it is alive.
  absl::StatusOr<SqliteStatement> Prepare(std::string_view sql);
  // The single integer a query returns (e.g. "PRAGMA user_version").
  absl::StatusOr<int64_t> QueryInt(std::string_view sql);

  int64_t LastInsertRowId() const;
  int Changes() const;
  sqlite3* handle() const { return db_; }
  const std::string& path() const { return path_; }

  // Error for the connection's last failed call.
  absl::Status LastError(int code, std::string_view context) const;

 private:
  SqliteConnection(sqlite3* db, std::string path) : db_(db), path_(std::move(path)) {}

  sqlite3* db_;
  std::string path_;
  std::unordered_map<std::string, sqlite3_stmt*> statements_;
};

}  // namespace surfmap
