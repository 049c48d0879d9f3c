// Row readers of the SQLite store: each table's column list beside the
// function that reads a row selected with it (kept side by side so they
// cannot drift apart), and a helper that collects every row of a statement.
#pragma once

#include <type_traits>
#include <vector>

#include "absl/status/statusor.h"
#include "server/base/status_macros.h"
#include "storage/records.h"
#include "storage/sqlite_connection.h"

namespace surfmap::sqlite {

inline constexpr char kObjectColumns[] =
    "id, name, mesh_format, control_vertices, control_faces, created_unix_ms, metadata_json, surface";
ObjectRecord ReadObject(const SqliteStatement& s, int first_column = 0);

inline constexpr char kJobColumns[] =
    "id, object_id, state, params_json, created_unix_ms, updated_unix_ms, metadata_json";
absl::StatusOr<JobRecord> ReadJob(const SqliteStatement& s, int first_column = 0);

inline constexpr char kCommandColumns[] =
    "id, job_id, site_level, site_vertex, command_json, state, lease_owner, "
    "lease_deadline_unix_ms, attempt, created_unix_ms";
inline constexpr int kCommandColumnCount = 10;
absl::StatusOr<CommandRecord> ReadCommand(const SqliteStatement& s, int first_column = 0);

// The samples column follows these when samples are wanted.
inline constexpr char kTraceColumns[] =
    "id, command_id, job_id, n_samples, sample_encoding, received_unix_ms, metadata_json, import_sha256";
inline constexpr int kTraceColumnCount = 8;
// `samples_column`: the index of the samples BLOB (with_samples only).
absl::StatusOr<TraceRecord> ReadTrace(const SqliteStatement& s, bool with_samples, int first_column = 0,
                                      int samples_column = kTraceColumnCount);

inline constexpr char kFitColumns[] =
    "id, trace_id, version, estimator_name, estimator_version, options_json, result_json, "
    "mu, a1, a2, sigma, created_unix_ms";
inline constexpr int kFitColumnCount = 12;
FitRecord ReadFit(const SqliteStatement& s, int first_column = 0);

inline constexpr char kEventColumns[] = "id, job_id, unix_ms, kind, detail_json";
EventRecord ReadEvent(const SqliteStatement& s);

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

}  // namespace surfmap::sqlite
