// The write steps of the SQLite store. Validation runs on the caller's thread
// before a write is queued; every other step runs on the writer thread inside
// the write's savepoint (see GroupCommitWriter), so a step that fails leaves
// nothing behind.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "server/base/status_macros.h"
#include "storage/records.h"
#include "storage/sqlite_connection.h"

namespace surfmap::sqlite {

// Adds context to an error without changing its code.
absl::Status Annotate(const absl::Status& status, std::string_view context);

// ---- Validation (caller's thread, before queuing) ----
absl::Status ValidateEvents(const std::vector<NewEvent>& events);
absl::Status ValidateFit(const NewFit& fit, const std::string& where);
absl::Status ValidateLease(const LeaseRequest& request);
// An import's fields (request.import set): its hash, source and command.
absl::Status ValidateImport(const AcceptTraceRequest& request);
// The frame the samples were sent in: "" or "object" with no registration,
// or a rig's frame ("rig_base", "rig_base_sensor_forces") with one. Checked
// before queuing: a bad frame found by the writer fails after the caller has
// changed its plan in memory (which then reloads, failing what is queued).
absl::Status ValidateFrame(const std::string& frame, int64_t registration_id);
// A file's SHA-256: 64 lower-case hex digits; the error names `field`.
absl::Status ValidateSha256(const std::string& sha256, absl::string_view field);

// ---- Steps (writer thread) ----
absl::StatusOr<JobRecord> LoadJob(SqliteConnection& db, int64_t job_id);
absl::StatusOr<CommandRecord> LoadCommand(SqliteConnection& db, int64_t command_id);
absl::Status InsertEvents(SqliteConnection& db, int64_t job_id, const std::vector<NewEvent>& events, int64_t now);
// `field` names the list in error messages ("commands", "new_commands").
absl::StatusOr<std::vector<int64_t>> InsertCommands(SqliteConnection& db, int64_t job_id,
                                                    const std::vector<NewCommand>& commands, int64_t now,
                                                    const std::string& field);
// One command already answered (an import's implied command: 'done' when
// stored, 'failed' when refused), inserted with its final state, owner and
// attempt 1 in one row write.
absl::StatusOr<int64_t> InsertAnsweredCommand(SqliteConnection& db, int64_t job_id, const NewCommand& command,
                                              const char* state, const std::string& owner, int64_t now,
                                              const std::string& field);
// FAILED_PRECONDITION unless the job takes imports (it is not cancelled or
// completed).
absl::Status CheckTakesImports(const JobRecord& job);
// Inserts the fit and returns it as the store now holds it, so writers answer
// with exactly what a later read gives (a NaN headline number reads as empty).
absl::StatusOr<FitRecord> InsertFit(SqliteConnection& db, int64_t trace_id, int32_t version, const NewFit& fit,
                                    int64_t now);
// FailedPrecondition if the transition from the stored state is not allowed.
absl::Status SetJobState(SqliteConnection& db, const JobRecord& job, JobState to, int64_t now);
// The checkpoint's revision, or the last journal entry's when there is one.
absl::StatusOr<int64_t> CurrentPlanRevision(SqliteConnection& db, int64_t job_id);

// A trace with its samples already encoded, so the writer thread only copies.
struct EncodedTrace {
  AcceptTraceRequest request;  // samples moved out
  int64_t n_samples = 0;
  std::string blob;
};
// See Store::AcceptTraceAsync (the idempotency rule) and AcceptTraceRequest.
absl::StatusOr<AcceptTraceResult> AcceptTraceWrite(SqliteConnection& db, const EncodedTrace& in, int64_t now);
absl::StatusOr<FailCommandResult> FailCommandWrite(SqliteConnection& db, const FailCommandRequest& req, int64_t now);
// The oldest leasable command (pending, or leased with an expired lease) of a
// running job, leased to request.owner; nullopt when there is none.
absl::StatusOr<std::optional<CommandRecord>> LeaseWrite(SqliteConnection& db, const LeaseRequest& request);

}  // namespace surfmap::sqlite
