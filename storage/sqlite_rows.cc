#include "storage/sqlite_rows.h"

#include "absl/strings/str_cat.h"

namespace surfmap::sqlite {

ObjectRecord ReadObject(const SqliteStatement& s, int c) {
  ObjectRecord r;
  r.id = s.ColumnInt(c + 0);
  r.name = s.ColumnText(c + 1);
  r.mesh_format = s.ColumnText(c + 2);
  r.control_vertices = s.ColumnInt(c + 3);
  r.control_faces = s.ColumnInt(c + 4);
  r.created_unix_ms = s.ColumnInt(c + 5);
  r.metadata_json = s.ColumnText(c + 6);
  r.surface = s.ColumnText(c + 7);
  return r;
}

absl::StatusOr<JobRecord> ReadJob(const SqliteStatement& s, int c) {
  JobRecord r;
  r.id = s.ColumnInt(c + 0);
  r.object_id = s.ColumnInt(c + 1);
  SURFMAP_ASSIGN_OR_RETURN(r.state, ParseJobState(s.ColumnText(c + 2)));
  r.params_json = s.ColumnText(c + 3);
  r.created_unix_ms = s.ColumnInt(c + 4);
  r.updated_unix_ms = s.ColumnInt(c + 5);
  r.metadata_json = s.ColumnText(c + 6);
  return r;
}

absl::StatusOr<CommandRecord> ReadCommand(const SqliteStatement& s, int c) {
  CommandRecord r;
  r.id = s.ColumnInt(c + 0);
  r.job_id = s.ColumnInt(c + 1);
  r.site_level = static_cast<int32_t>(s.ColumnInt(c + 2));
  r.site_vertex = s.ColumnInt(c + 3);
  r.command_json = s.ColumnText(c + 4);
  SURFMAP_ASSIGN_OR_RETURN(r.state, ParseCommandState(s.ColumnText(c + 5)));
  r.lease_owner = s.ColumnText(c + 6);
  r.lease_deadline_unix_ms = s.ColumnInt(c + 7);
  r.attempt = static_cast<int32_t>(s.ColumnInt(c + 8));
  r.created_unix_ms = s.ColumnInt(c + 9);
  return r;
}

absl::StatusOr<TraceRecord> ReadTrace(const SqliteStatement& s, bool with_samples, int c, int samples_column) {
  TraceRecord r;
  r.id = s.ColumnInt(c + 0);
  r.command_id = s.ColumnInt(c + 1);
  r.job_id = s.ColumnInt(c + 2);
  r.n_samples = s.ColumnInt(c + 3);
  r.received_unix_ms = s.ColumnInt(c + 5);
  r.metadata_json = s.ColumnText(c + 6);
  r.import_sha256 = s.ColumnText(c + 7);  // NULL (a leased trace) reads as ""
  if (with_samples) {
    if (s.ColumnInt(c + 4) != kSampleEncodingPackedLE) {
      return absl::DataLossError(absl::StrCat("trace ", r.id, " has unknown sample encoding ", s.ColumnInt(c + 4)));
    }
    absl::StatusOr<std::vector<StoredSample>> samples = DecodeSamples(s.ColumnBlob(samples_column));
    if (!samples.ok() || static_cast<int64_t>(samples->size()) != r.n_samples) {
      return absl::DataLossError(absl::StrCat(
          "trace ", r.id, ": stored samples do not decode to n_samples=", r.n_samples,
          samples.ok() ? "" : absl::StrCat(" (", samples.status().message(), ")")));
    }
    r.samples = std::move(*samples);
  }
  return r;
}

FitRecord ReadFit(const SqliteStatement& s, int c) {
  FitRecord r;
  r.id = s.ColumnInt(c + 0);
  r.trace_id = s.ColumnInt(c + 1);
  r.version = static_cast<int32_t>(s.ColumnInt(c + 2));
  r.estimator_name = s.ColumnText(c + 3);
  r.estimator_version = s.ColumnText(c + 4);
  r.options_json = s.ColumnText(c + 5);
  r.result_json = s.ColumnText(c + 6);
  r.mu = s.ColumnOptionalDouble(c + 7);
  r.a1 = s.ColumnOptionalDouble(c + 8);
  r.a2 = s.ColumnOptionalDouble(c + 9);
  r.sigma = s.ColumnOptionalDouble(c + 10);
  r.created_unix_ms = s.ColumnInt(c + 11);
  return r;
}

EventRecord ReadEvent(const SqliteStatement& s) {
  EventRecord r;
  r.id = s.ColumnInt(0);
  r.job_id = s.ColumnIsNull(1) ? 0 : s.ColumnInt(1);
  r.unix_ms = s.ColumnInt(2);
  r.kind = s.ColumnText(3);
  r.detail_json = s.ColumnText(4);
  return r;
}

}  // namespace surfmap::sqlite
