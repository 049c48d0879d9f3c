#include "storage/schema.h"

#include <sqlite3.h>

#include "gtest/gtest.h"
#include "storage/sqlite_store.h"
#include "storage/temp_db_dir_for_test.h"

namespace surfmap {
namespace {

std::unique_ptr<SqliteConnection> OpenRaw(const std::string& path) {
  absl::StatusOr<std::unique_ptr<SqliteConnection>> db = SqliteConnection::Open(path, {});
  EXPECT_TRUE(db.ok()) << db.status();
  return db.ok() ? std::move(*db) : nullptr;
}

int64_t QueryInt(SqliteConnection& db, const std::string& sql) {
  absl::StatusOr<int64_t> v = db.QueryInt(sql);
  EXPECT_TRUE(v.ok()) << sql << ": " << v.status();
  return v.ok() ? *v : -1;
}

TEST(SchemaTest, MigratesEmptyFileToLatestVersion) {
  TempDbDir dir;
  auto db = OpenRaw(dir.Path("a.db"));
  ASSERT_EQ(QueryInt(*db, "PRAGMA user_version"), 0);
  ASSERT_TRUE(ApplyMigrations(*db, SchemaMigrations()).ok());
  EXPECT_EQ(QueryInt(*db, "PRAGMA user_version"),
            static_cast<int64_t>(SchemaMigrations().size()));
  EXPECT_EQ(QueryInt(*db, "PRAGMA application_id"), kSurfmapApplicationId);
  for (const char* table : {"objects", "jobs", "plans", "commands", "traces", "fits", "events", "rig_registrations",
                            "trace_frames"}) {
    EXPECT_EQ(QueryInt(*db, std::string("SELECT COUNT(*) FROM sqlite_master WHERE type='table' "
                                        "AND name='") + table + "'"),
              1)
        << table;
  }
  // A second run is a no-op.
  ASSERT_TRUE(ApplyMigrations(*db, SchemaMigrations()).ok());
}

// Version 6 on a version-5 file: a rejected trace stored before it reads as
// sent in the object's frame with no file hash; a file's hash is unique per
// job among rejected traces, traces without one (not imports) are not.
TEST(SchemaTest, Version6KeepsOlderRejectedTracesAndRefusedFilesOncePerJob) {
  TempDbDir dir;
  auto db = OpenRaw(dir.Path("a.db"));
  ASSERT_GE(SchemaMigrations().size(), 6u);
  ASSERT_TRUE(ApplyMigrations(*db, SchemaMigrations().first(5)).ok());
  ASSERT_TRUE(db->Exec("PRAGMA foreign_keys = OFF").ok());  // rows without their job and command
  ASSERT_TRUE(db->Exec("INSERT INTO rejected_traces (command_id, job_id, rig_id, check_name, message, n_samples, "
                       "sample_encoding, received_unix_ms, samples) VALUES (1, 1, 'arm', 'offset', 'm', 1, 1, 0, x'00')")
                  .ok());
  ASSERT_TRUE(ApplyMigrations(*db, SchemaMigrations()).ok());
  EXPECT_EQ(QueryInt(*db, "SELECT COUNT(*) FROM rejected_traces WHERE import_sha256 IS NULL AND frame = 'object' "
                          "AND registration_id = 0"),
            1);
  const std::string insert =
      "INSERT INTO rejected_traces (command_id, job_id, rig_id, check_name, message, n_samples, sample_encoding, "
      "received_unix_ms, samples, import_sha256) VALUES (1, 1, 'hand', 'surface', 'm', 1, 1, 0, x'00', ";
  EXPECT_TRUE(db->Exec(insert + "NULL)").ok());  // a second trace without a hash
  EXPECT_TRUE(db->Exec(insert + "'aa')").ok());
  EXPECT_FALSE(db->Exec(insert + "'aa')").ok()) << "the same refused file kept twice in one job";
  EXPECT_FALSE(db->Exec("UPDATE rejected_traces SET frame = 'tool' WHERE id = 1").ok()) << "an unknown frame";
}

TEST(SchemaTest, ConnectionSettingsAreDurableWalWithForeignKeys) {
  TempDbDir dir;
  auto db = OpenRaw(dir.Path("a.db"));
  ASSERT_TRUE(ApplyMigrations(*db, SchemaMigrations()).ok());
  EXPECT_EQ(QueryInt(*db, "PRAGMA page_size"), 16384);
  absl::StatusOr<SqliteStatement> mode = db->Prepare("PRAGMA journal_mode");
  ASSERT_TRUE(mode.ok());
  ASSERT_TRUE(*mode->Step());
  EXPECT_EQ(mode->ColumnText(0), "wal");
  EXPECT_EQ(QueryInt(*db, "PRAGMA synchronous"), 2);  // FULL
  EXPECT_EQ(QueryInt(*db, "PRAGMA foreign_keys"), 1);
  EXPECT_EQ(QueryInt(*db, "PRAGMA busy_timeout"), 5000);
}

TEST(SchemaTest, ForeignKeysAreEnforced) {
  TempDbDir dir;
  auto db = OpenRaw(dir.Path("a.db"));
  ASSERT_TRUE(ApplyMigrations(*db, SchemaMigrations()).ok());
  absl::Status s = db->Exec(
      "INSERT INTO jobs (object_id, state, params_json, created_unix_ms, updated_unix_ms) "
      "VALUES (42, 'running', '{}', 0, 0)");
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.message().find("FOREIGN KEY"), std::string::npos) << s;
  s = db->Exec(
      "INSERT INTO traces (command_id, job_id, n_samples, sample_encoding, received_unix_ms, "
      "samples) VALUES (7, 7, 1, 1, 0, x'00')");
  EXPECT_FALSE(s.ok());
  EXPECT_EQ(QueryInt(*db, "SELECT COUNT(*) FROM jobs") + QueryInt(*db, "SELECT COUNT(*) FROM traces"),
            0);
}

// Version 7 on a version-6 file: an object stored before is a control mesh
// (what it was planned as), and a surface outside the two kinds is refused.
TEST(SchemaTest, Version7ReadsOlderObjectsAsControlMeshes) {
  TempDbDir dir;
  auto db = OpenRaw(dir.Path("a.db"));
  ASSERT_GE(SchemaMigrations().size(), 7u);
  ASSERT_TRUE(ApplyMigrations(*db, SchemaMigrations().first(6)).ok());
  ASSERT_TRUE(db->Exec("INSERT INTO objects (id, name, mesh_format, control_vertices, "
                       "control_faces, created_unix_ms, mesh_bytes) VALUES (1,'o','obj',0,0,0,x'00')")
                  .ok());
  ASSERT_TRUE(ApplyMigrations(*db, SchemaMigrations()).ok());
  EXPECT_EQ(QueryInt(*db, "SELECT COUNT(*) FROM objects WHERE surface = 'control_mesh'"), 1);
  EXPECT_TRUE(db->Exec("UPDATE objects SET surface = 'facets' WHERE id = 1").ok());
  EXPECT_FALSE(db->Exec("UPDATE objects SET surface = 'nurbs' WHERE id = 1").ok());
}

TEST(SchemaTest, InvalidJsonAndStatesAreRejectedByChecks) {
  TempDbDir dir;
  auto db = OpenRaw(dir.Path("a.db"));
  ASSERT_TRUE(ApplyMigrations(*db, SchemaMigrations()).ok());
  ASSERT_TRUE(db->Exec("INSERT INTO objects (id, name, mesh_format, control_vertices, "
                       "control_faces, created_unix_ms, mesh_bytes) VALUES (1,'o','obj',0,0,0,x'00')")
                  .ok());
  absl::Status s = db->Exec(
      "INSERT INTO jobs (object_id, state, params_json, created_unix_ms, updated_unix_ms) "
      "VALUES (1, 'running', '{not json', 0, 0)");
  EXPECT_EQ(s.code(), absl::StatusCode::kInvalidArgument) << s;
  s = db->Exec(
      "INSERT INTO jobs (object_id, state, params_json, created_unix_ms, updated_unix_ms) "
      "VALUES (1, 'sleeping', '{}', 0, 0)");
  EXPECT_EQ(s.code(), absl::StatusCode::kInvalidArgument) << s;
}

TEST(SchemaTest, NewerDatabaseIsRefused) {
  TempDbDir dir;
  const std::string path = dir.Path("a.db");
  {
    auto db = OpenRaw(path);
    ASSERT_TRUE(ApplyMigrations(*db, SchemaMigrations()).ok());
    ASSERT_TRUE(db->Exec("PRAGMA user_version = 99").ok());
  }
  absl::StatusOr<std::unique_ptr<SqliteStore>> store = SqliteStore::Open(path);
  ASSERT_FALSE(store.ok());
  EXPECT_EQ(store.status().code(), absl::StatusCode::kFailedPrecondition);
  EXPECT_NE(store.status().message().find("schema version 99"), std::string::npos)
      << store.status();
  EXPECT_NE(store.status().message().find("newer"), std::string::npos);
  // Refusing did not change the file.
  auto db = OpenRaw(path);
  EXPECT_EQ(QueryInt(*db, "PRAGMA user_version"), 99);
}

TEST(SchemaTest, ForeignApplicationIdIsRefused) {
  TempDbDir dir;
  auto db = OpenRaw(dir.Path("a.db"));
  ASSERT_TRUE(db->Exec("PRAGMA application_id = 1234").ok());
  absl::Status s = ApplyMigrations(*db, SchemaMigrations());
  EXPECT_EQ(s.code(), absl::StatusCode::kFailedPrecondition) << s;
  EXPECT_NE(s.message().find("not a surfmap database"), std::string::npos) << s;
}

TEST(SchemaTest, StepsApplyInOrderAndAFailingStepRollsBackAlone) {
  TempDbDir dir;
  auto db = OpenRaw(dir.Path("a.db"));
  const Migration good[] = {
      {1, "create a", "CREATE TABLE a (x INTEGER)"},
      {2, "fill a", "INSERT INTO a VALUES (1); INSERT INTO a VALUES (2)"},
  };
  ASSERT_TRUE(ApplyMigrations(*db, good).ok());
  EXPECT_EQ(QueryInt(*db, "PRAGMA user_version"), 2);
  EXPECT_EQ(QueryInt(*db, "SELECT SUM(x) FROM a"), 3);

  // Step 3 creates a table, then fails: neither the table nor version 3 stay.
  const Migration with_bad_step[] = {
      good[0],
      good[1],
      {3, "broken", "CREATE TABLE b (y INTEGER); INSERT INTO no_such_table VALUES (1)"},
  };
  absl::Status s = ApplyMigrations(*db, with_bad_step);
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.message().find("migration to version 3 (broken)"), std::string::npos) << s;
  EXPECT_EQ(QueryInt(*db, "PRAGMA user_version"), 2);
  EXPECT_EQ(QueryInt(*db, "SELECT COUNT(*) FROM sqlite_master WHERE name = 'b'"), 0);
}

TEST(SchemaTest, MisnumberedListIsRejected) {
  TempDbDir dir;
  auto db = OpenRaw(dir.Path("a.db"));
  const Migration list[] = {{1, "a", "SELECT 1"}, {3, "c", "SELECT 1"}};
  absl::Status s = ApplyMigrations(*db, list);
  EXPECT_EQ(s.code(), absl::StatusCode::kInvalidArgument) << s;
  EXPECT_EQ(QueryInt(*db, "PRAGMA user_version"), 0);
}

TEST(SchemaTest, UnopenablePathIsUnavailableAndNamed) {
  absl::StatusOr<std::unique_ptr<SqliteStore>> store =
      SqliteStore::Open("/nonexistent-dir-surfmap/x.db");
  ASSERT_FALSE(store.ok());
  EXPECT_EQ(store.status().code(), absl::StatusCode::kUnavailable) << store.status();
  EXPECT_NE(store.status().message().find("/nonexistent-dir-surfmap/x.db"), std::string::npos);
}

}  // namespace
}  // namespace surfmap
