// The database schema as an ordered list of migration steps.
//
// The schema version is PRAGMA user_version (0 = empty file). Opening applies
// every step whose version is above the file's, each in its own transaction
// together with the new user_version, so a crash mid-upgrade leaves the file at
// the last completed step. A file whose version is above the last step this
// build knows is refused (it was written by a newer surfmap). Steps are never
// edited once released: a change is a new step appended to the list.
#pragma once

#include <span>
#include <string_view>

#include "absl/status/status.h"
#include "storage/sqlite_connection.h"

namespace surfmap {

struct Migration {
  int version;                  // 1, 2, 3, ... in list order
  std::string_view description;
  std::string_view sql;         // statements run inside the step's transaction
};

// PRAGMA application_id of a surfmap database ("SFMP"); a file with another
// non-zero id is refused.
inline constexpr int kSurfmapApplicationId = 0x53464d50;

// The schema of this build.
std::span<const Migration> SchemaMigrations();

// Brings the database to the last version of `migrations`.
// FailedPrecondition if the file is newer than the list or belongs to another
// application; InvalidArgument if the list is not numbered 1, 2, 3, ...;
// the SQLite error (naming the step) if a step fails, with that step rolled back.
absl::Status ApplyMigrations(SqliteConnection& db, std::span<const Migration> migrations);

}  // namespace surfmap
