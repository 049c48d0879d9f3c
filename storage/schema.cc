#include "storage/schema.h"

#include "absl/strings/str_cat.h"

namespace surfmap {
namespace {

// Column order: large BLOBs last, so reading the small columns of a row never
// touches its overflow pages. Every *_json column must hold valid JSON.
constexpr std::string_view kInitialSchema = R"sql(
CREATE TABLE objects (
  id                INTEGER PRIMARY KEY,
  name              TEXT    NOT NULL,
  mesh_format       TEXT    NOT NULL CHECK (mesh_format IN ('obj', 'ply')),
  control_vertices  INTEGER NOT NULL CHECK (control_vertices >= 0),
  control_faces     INTEGER NOT NULL CHECK (control_faces >= 0),
  created_unix_ms   INTEGER NOT NULL,
  mesh_bytes        BLOB    NOT NULL
);

CREATE TABLE jobs (
  id                INTEGER PRIMARY KEY,
  object_id         INTEGER NOT NULL REFERENCES objects (id),
  state             TEXT    NOT NULL
                    CHECK (state IN ('running', 'paused', 'completed', 'cancelled')),
  params_json       TEXT    NOT NULL CHECK (json_valid(params_json)),
  created_unix_ms   INTEGER NOT NULL,
  updated_unix_ms   INTEGER NOT NULL
);
CREATE INDEX jobs_by_object ON jobs (object_id, id);

CREATE TABLE plans (
  job_id            INTEGER PRIMARY KEY REFERENCES jobs (id),
  revision          INTEGER NOT NULL CHECK (revision >= 1),
  updated_unix_ms   INTEGER NOT NULL,
  plan_json         TEXT    NOT NULL CHECK (json_valid(plan_json))
);

CREATE TABLE commands (
  id                     INTEGER PRIMARY KEY,
  job_id                 INTEGER NOT NULL REFERENCES jobs (id),
  site_level             INTEGER NOT NULL CHECK (site_level >= 0),
  site_vertex            INTEGER NOT NULL CHECK (site_vertex >= 0),
  state                  TEXT    NOT NULL
                         CHECK (state IN ('pending', 'leased', 'done', 'failed')),
  lease_owner            TEXT    NOT NULL DEFAULT '',
  lease_deadline_unix_ms INTEGER NOT NULL DEFAULT 0,
  attempt                INTEGER NOT NULL DEFAULT 0,
  created_unix_ms        INTEGER NOT NULL,
  command_json           TEXT    NOT NULL CHECK (json_valid(command_json))
);
CREATE INDEX commands_by_job ON commands (job_id, id);
-- Leasing scans only pending and leased commands, oldest first.
CREATE INDEX commands_leasable ON commands (state, id) WHERE state IN ('pending', 'leased');

CREATE TABLE traces (
  id                INTEGER PRIMARY KEY,
  command_id        INTEGER NOT NULL UNIQUE REFERENCES commands (id),
  job_id            INTEGER NOT NULL REFERENCES jobs (id),
  n_samples         INTEGER NOT NULL CHECK (n_samples > 0),
  sample_encoding   INTEGER NOT NULL,
  received_unix_ms  INTEGER NOT NULL,
  samples           BLOB    NOT NULL
);
CREATE INDEX traces_by_job ON traces (job_id, id);

CREATE TABLE fits (
  id                INTEGER PRIMARY KEY,
  trace_id          INTEGER NOT NULL REFERENCES traces (id),
  version           INTEGER NOT NULL CHECK (version >= 1),
  estimator_name    TEXT    NOT NULL,
  estimator_version TEXT    NOT NULL,
  mu                REAL,
  a1                REAL,
  a2                REAL,
  sigma             REAL,
  created_unix_ms   INTEGER NOT NULL,
  options_json      TEXT    NOT NULL CHECK (json_valid(options_json)),
  result_json       TEXT    NOT NULL CHECK (json_valid(result_json)),
  UNIQUE (trace_id, version)
);

-- AUTOINCREMENT: event ids never go back, so "events after id N" is a cursor.
CREATE TABLE events (
  id                INTEGER PRIMARY KEY AUTOINCREMENT,
  job_id            INTEGER REFERENCES jobs (id),
  unix_ms           INTEGER NOT NULL,
  kind              TEXT    NOT NULL CHECK (kind <> ''),
  detail_json       TEXT    NOT NULL CHECK (json_valid(detail_json))
);
CREATE INDEX events_by_job ON events (job_id, id);
)sql";

// Version 2: the plan as checkpoint + journal, so an accepted trace appends a
// small entry instead of rewriting the whole plan (see PlanRecord); and the
// leasable commands per job, so a rig leasing for one job does not scan the
// pending commands of every older job.
constexpr char kPlanJournal[] = R"sql(
CREATE INDEX commands_leasable_by_job ON commands (job_id, id) WHERE state IN ('pending', 'leased');

CREATE TABLE plan_journal (
  job_id            INTEGER NOT NULL REFERENCES jobs (id),
  revision          INTEGER NOT NULL CHECK (revision >= 2),
  entry_json        TEXT    NOT NULL CHECK (json_valid(entry_json)),
  PRIMARY KEY (job_id, revision)
) WITHOUT ROWID;
)sql";

// Version 3: traces refused as implausible for their command, kept (out of
// the map) so an operator can see what a rig sent and why it was refused.
constexpr char kRejectedTraces[] = R"sql(
CREATE TABLE rejected_traces (
  id                INTEGER PRIMARY KEY,
  command_id        INTEGER NOT NULL REFERENCES commands (id),
  job_id            INTEGER NOT NULL REFERENCES jobs (id),
  rig_id            TEXT    NOT NULL,
  check_name        TEXT    NOT NULL,
  message           TEXT    NOT NULL,
  n_samples         INTEGER NOT NULL CHECK (n_samples > 0),
  sample_encoding   INTEGER NOT NULL,
  received_unix_ms  INTEGER NOT NULL,
  samples           BLOB    NOT NULL
);
CREATE INDEX rejected_traces_by_job ON rejected_traces (job_id, id);
CREATE INDEX rejected_traces_by_command ON rejected_traces (command_id);
)sql";

// Version 4 (import and provenance, issues 13 and 14): lab metadata
// (operator, specimen, probe tip, sensor, notes, lab keys) kept with objects,
// jobs and traces as a JSON object the service defines; traces recorded
// elsewhere and imported into a job (not answers to a leased command) carry
// the SHA-256 of their file, unique per job, so importing a file twice
// stores it once.
constexpr char kImportAndProvenance[] = R"sql(
ALTER TABLE objects ADD COLUMN metadata_json TEXT NOT NULL DEFAULT '{}' CHECK (json_valid(metadata_json));
ALTER TABLE jobs ADD COLUMN metadata_json TEXT NOT NULL DEFAULT '{}' CHECK (json_valid(metadata_json));
ALTER TABLE traces ADD COLUMN metadata_json TEXT NOT NULL DEFAULT '{}' CHECK (json_valid(metadata_json));
ALTER TABLE traces ADD COLUMN import_sha256 TEXT;
CREATE UNIQUE INDEX traces_imported_by_job ON traces (job_id, import_sha256) WHERE import_sha256 IS NOT NULL;
)sql";

// Version 5: frames and calibration. A rig's registration to an object (the
// object's pose in the rig's base frame, tip radius, sensor orientation, as
// JSON), append-only per (object, rig); and, for traces sent in a rig's
// frame, that frame and the registration they were converted with (traces
// in the object's frame, all of them before version 5, have no row).
constexpr char kRigRegistrations[] = R"sql(
CREATE TABLE rig_registrations (
  id                INTEGER PRIMARY KEY,
  object_id         INTEGER NOT NULL REFERENCES objects (id),
  rig_name          TEXT    NOT NULL CHECK (rig_name <> ''),
  version           INTEGER NOT NULL CHECK (version >= 1),
  created_unix_ms   INTEGER NOT NULL,
  registration_json TEXT    NOT NULL CHECK (json_valid(registration_json)),
  UNIQUE (object_id, rig_name, version)
);

CREATE TABLE trace_frames (
  trace_id          INTEGER PRIMARY KEY REFERENCES traces (id),
  frame             TEXT    NOT NULL CHECK (frame IN ('rig_base', 'rig_base_sensor_forces')),
  registration_id   INTEGER NOT NULL REFERENCES rig_registrations (id)
);
)sql";

// Version 6 (review fixes): a refused import is kept once per file and job
// (the file's SHA-256, unique per job like an accepted import's), so
// importing a refused file again writes nothing; and a rejected trace keeps
// the frame it was sent in and the registration it was converted with, as an
// accepted one does (trace_frames). Rows before version 6 have neither: NULL
// hash, frame 'object', registration 0.
constexpr char kRejectedImportsAndFrames[] = R"sql(
ALTER TABLE rejected_traces ADD COLUMN import_sha256 TEXT;
ALTER TABLE rejected_traces ADD COLUMN frame TEXT NOT NULL DEFAULT 'object'
  CHECK (frame IN ('object', 'rig_base', 'rig_base_sensor_forces'));
ALTER TABLE rejected_traces ADD COLUMN registration_id INTEGER NOT NULL DEFAULT 0;
CREATE UNIQUE INDEX rejected_traces_by_import ON rejected_traces (job_id, import_sha256)
  WHERE import_sha256 IS NOT NULL;
)sql";

// Version 7: what an object's mesh is. 'control_mesh' (every object before):
// a Loop control mesh whose smooth limit surface is the object, or a dense
// scan that is the surface itself; 'facets': a faceted mesh (a CAD export)
// whose flat triangles are the surface, sharp edges and all.
constexpr char kObjectSurface[] = R"sql(
ALTER TABLE objects ADD COLUMN surface TEXT NOT NULL DEFAULT 'control_mesh'
  CHECK (surface IN ('control_mesh', 'facets'));
)sql";

constexpr Migration kMigrations[] = {
    {1, "initial schema: objects, jobs, plans, commands, traces, fits, events", kInitialSchema},
    {2, "plan journal after the plan's checkpoint; leasable commands by job", kPlanJournal},
    {3, "traces refused as implausible, kept out of the map", kRejectedTraces},
    {4, "provenance metadata on objects, jobs and traces; imported traces by file hash", kImportAndProvenance},
    {5, "rig registrations (frames and calibration); the frame of traces sent in a rig's frame", kRigRegistrations},
    {6, "refused imports kept once per file and job; the frame and registration of rejected traces",
     kRejectedImportsAndFrames},
    {7, "what an object's mesh is: a control mesh (or scan), or facets that are the surface", kObjectSurface},
};

}  // namespace

std::span<const Migration> SchemaMigrations() { return kMigrations; }

absl::Status ApplyMigrations(SqliteConnection& db, std::span<const Migration> migrations) {
  for (size_t i = 0; i < migrations.size(); ++i) {
    if (migrations[i].version != static_cast<int>(i) + 1) {
      return absl::InvalidArgumentError(
          absl::StrCat("migration list entry ", i, " has version ", migrations[i].version,
                       ", expected ", i + 1));
    }
  }
  const int latest = static_cast<int>(migrations.size());

  absl::StatusOr<int64_t> app_id = db.QueryInt("PRAGMA application_id");
  if (!app_id.ok()) return app_id.status();
  if (*app_id != 0 && *app_id != kSurfmapApplicationId) {
    return absl::FailedPreconditionError(
        absl::StrCat("database '", db.path(), "' is not a surfmap database (application_id ",
                     *app_id, ")"));
  }

  while (true) {
    // BEGIN IMMEDIATE: read the version under the write lock, so two processes
    // opening the same new file do not both apply a step.
    if (absl::Status s = db.Exec("BEGIN IMMEDIATE"); !s.ok()) return s;
    absl::StatusOr<int64_t> current = db.QueryInt("PRAGMA user_version");
    if (!current.ok()) {
      db.Exec("ROLLBACK").IgnoreError();
      return current.status();
    }
    if (*current > latest) {
      db.Exec("ROLLBACK").IgnoreError();
      return absl::FailedPreconditionError(absl::StrCat(
          "database '", db.path(), "' has schema version ", *current,
          " but this build of surfmap knows versions up to ", latest,
          "; it was written by a newer surfmap: upgrade surfmap, do not downgrade"));
    }
    if (*current == latest) return db.Exec("COMMIT");

    const Migration& step = migrations[*current];
    absl::Status s = db.Exec(step.sql);
    if (s.ok()) {
      s = db.Exec(absl::StrCat("PRAGMA user_version = ", step.version,
                               "; PRAGMA application_id = ", kSurfmapApplicationId));
    }
    if (s.ok()) s = db.Exec("COMMIT");
    if (!s.ok()) {
      db.Exec("ROLLBACK").IgnoreError();
      return absl::Status(s.code(), absl::StrCat("schema migration to version ", step.version,
                                                 " (", std::string(step.description), "): ", s.message()));
    }
  }
}

}  // namespace surfmap
