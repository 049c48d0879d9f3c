#include "tests/support/db_snapshot.h"

#include <sqlite3.h>

#include <vector>

#include "absl/strings/str_cat.h"

namespace surfmap::itest {
namespace {

struct Db {
  sqlite3* handle = nullptr;
  ~Db() { sqlite3_close_v2(handle); }
};

absl::Status Error(sqlite3* db, const std::string& what) {
  return absl::InternalError(absl::StrCat(what, ": ", db ? sqlite3_errmsg(db) : "no connection"));
}

// Runs `sql` and appends every row's columns, '|'-separated, one line per row.
absl::Status Dump(sqlite3* db, const std::string& sql, std::string* out) {
  sqlite3_stmt* stmt = nullptr;
  if (sqlite3_prepare_v2(db, sql.c_str(), -1, &stmt, nullptr) != SQLITE_OK) return Error(db, sql);
  int rc;
  while ((rc = sqlite3_step(stmt)) == SQLITE_ROW) {
    for (int c = 0; c < sqlite3_column_count(stmt); ++c) {
      const unsigned char* text = sqlite3_column_text(stmt, c);
      absl::StrAppend(out, c ? "|" : "", text ? reinterpret_cast<const char*>(text) : "NULL");
    }
    out->push_back('\n');
  }
  sqlite3_finalize(stmt);
  if (rc != SQLITE_DONE) return Error(db, sql);
  return absl::OkStatus();
}

}  // namespace

absl::StatusOr<DbSnapshot> TakeDbSnapshot(const std::string& db_path) {
  Db db;
  if (sqlite3_open_v2(db_path.c_str(), &db.handle, SQLITE_OPEN_READONLY, nullptr) != SQLITE_OK) {
    return Error(db.handle, "open " + db_path);
  }
  sqlite3_busy_timeout(db.handle, 10'000);
  DbSnapshot snapshot;
  std::string tables;
  if (absl::Status s = Dump(db.handle,
                            "SELECT name FROM sqlite_master WHERE type = 'table' AND name NOT LIKE 'sqlite_%' "
                            "ORDER BY name",
                            &tables);
      !s.ok()) {
    return s;
  }
  size_t start = 0;
  while (start < tables.size()) {
    size_t end = tables.find('\n', start);
    std::string table = tables.substr(start, end - start);
    start = end + 1;
    std::string count;
    if (absl::Status s = Dump(db.handle, absl::StrCat("SELECT COUNT(*) FROM \"", table, "\""), &count); !s.ok()) {
      return s;
    }
    snapshot.row_counts[table] = std::stoll(count);
  }
  if (snapshot.row_counts.count("commands")) {
    if (absl::Status s = Dump(db.handle, "SELECT id, state, lease_owner, attempt FROM commands ORDER BY id",
                              &snapshot.command_and_job_states);
        !s.ok()) {
      return s;
    }
  }
  if (snapshot.row_counts.count("jobs")) {
    if (absl::Status s = Dump(db.handle, "SELECT id, state FROM jobs ORDER BY id", &snapshot.command_and_job_states);
        !s.ok()) {
      return s;
    }
  }
  return snapshot;
}

std::string DbSnapshot::DifferenceTo(const DbSnapshot& after) const {
  std::string diff;
  for (const auto& [table, count] : row_counts) {
    auto it = after.row_counts.find(table);
    int64_t now = it == after.row_counts.end() ? -1 : it->second;
    if (now != count) absl::StrAppend(&diff, table, ": ", count, " -> ", now, " rows; ");
  }
  for (const auto& [table, count] : after.row_counts) {
    if (!row_counts.count(table)) absl::StrAppend(&diff, "new table ", table, "; ");
  }
  if (command_and_job_states != after.command_and_job_states) {
    absl::StrAppend(&diff, "command/job states changed:\n--- before\n", command_and_job_states, "--- after\n",
                    after.command_and_job_states);
  }
  return diff;
}

}  // namespace surfmap::itest
