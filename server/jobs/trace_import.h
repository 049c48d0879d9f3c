// Importing a drag recorded elsewhere (by hand, by another program: a
// positioned trace CSV, docs/trace-format.md) into a job's map (issue 13).
//
// The drag answers no leased command, so it is located on the job's surface
// (import_locate.h) and the command it implies goes through the same checks
// as a rig's trace (trace_plausibility.h), plus one a leased trace does not
// need: every sample near the surface. It is fitted with the job's estimator
// settings and, in one durable write (Store::AcceptTraceAsync with a
// TraceImport), stored with its implied command (done, measured by
// `source`), its fit, its provenance and its file's SHA-256, and recorded in
// the plan as an imported drag (PlanJournalEntry::kImport). So it is a sample
// like any other (ListSamples, GetSample, GetTrace, RefitJob, the map: its
// pieces join SamplingPlan::MeasuredPieces) and survives a restart (the plan's
// journal and checkpoint carry it).
//
// It marks no planned site measured and takes none of the sample budget: a
// drag placed by hand is rarely where a site is, and a site marked measured
// by a drag across it at another angle would hide what the planner wanted to
// learn there. The boundary planner's next choices do see its pieces.
//
// Refused drags are kept as rejected traces (ListRejectedTraces) with their
// implied command, failed, naming the source. Importing the same file (same
// SHA-256) into the same job again answers already_imported with the stored
// trace, whatever the job's state now. Only running or paused jobs take
// imports.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string>

#include "absl/status/statusor.h"
#include "server/estimate/drag_trace.h"
#include "server/estimate/fit_trace.h"
#include "server/jobs/job_executors.h"
#include "server/jobs/job_registry.h"
#include "server/jobs/provenance.h"
#include "storage/store.h"

namespace surfmap {

struct TraceImportRequest {
  int64_t job_id = 0;
  std::string source;           // who or what recorded it: 1..100 characters, one line
  std::string file_name;        // 0..500 characters, one line
  int64_t recorded_unix_ms = 0; // when it was recorded, as the client says; 0 = unknown
  Provenance provenance;
  std::string file_sha256;      // of the file's bytes (hex): set by the importer
};

// The SHA-256 of `bytes`, 64 lower-case hex digits.
std::string Sha256Hex(std::string_view bytes);

// RESOURCE_EXHAUSTED when `csv` has more non-blank lines than a trace of
// max_samples samples may (its header and up to 100 comment lines besides;
// blank lines, which the reader skips, do not count): counted without
// allocating, before the reader builds the trace.
absl::Status CheckCsvSize(std::string_view csv, int max_samples);

// The sample as stored: command = the implied command, received = when it was
// imported, metadata_json = ImportMetadataJson.
struct TraceImportOutcome : AcceptedSample {
  ProbeCommand probe;           // the implied command's decoded form
  bool already_imported = false;
  std::shared_ptr<const TraceFit> decoded_fit;  // null for a repeat
};

// INVALID_ARGUMENT naming the field (file_sha256 is not checked: the importer sets it).
absl::Status ValidateTraceImportRequest(const TraceImportRequest& request);

// The trace's metadata_json: {"provenance": {...}, "import": {"source",
// "file_name", "file_sha256", "recorded_unix_ms"}}.
std::string ImportMetadataJson(const TraceImportRequest& request);

class TraceImporter {
 public:
  TraceImporter(Store* store, JobRegistry* registry, JobExecutors executors);

  using Callback = std::function<void(absl::StatusOr<TraceImportOutcome>)>;
  // On the probe pool: hashes the file, answers a file already imported into
  // the job, bounds (CheckCsvSize) and reads it (ParseTraceCsv), locates,
  // checks and fits it, queues one write under the job's lock and answers
  // once it is durable. UNAVAILABLE when the pool is full. While the job is
  // being re-read after a failed write, the import waits for the re-read.
  void Import(TraceImportRequest request, std::shared_ptr<const std::string> csv, int max_samples, Callback done);

 private:
  // Runs LocateFitAndQueue on the probe pool; UNAVAILABLE when it is full.
  void SubmitImport(TraceImportRequest request, std::shared_ptr<const std::string> csv, int max_samples, bool may_wait,
                    Callback done);
  // With may_wait, an import that finds its job waiting to be re-read after
  // a failed write is submitted again once the re-read ends (or answered
  // why it failed); without, it is answered UNAVAILABLE.
  void LocateFitAndQueue(TraceImportRequest request, std::shared_ptr<const std::string> csv, int max_samples,
                         bool may_wait, Callback done);
  void KeepRejected(const TraceImportRequest& request, const std::shared_ptr<JobRuntime>& runtime,
                    const ProbeCommand& implied, const DragTrace& trace, const absl::Status& refusal, Callback done);
  absl::Status QueueImport(const TraceImportRequest& request, const std::shared_ptr<JobRuntime>& runtime,
                           const ProbeCommand& implied, const TraceFit& fit, const DragTrace& trace, Callback& done);
  void AnswerStored(int64_t trace_id, Callback done);

  Store* const store_;
  JobRegistry* const registry_;
  const JobExecutors executors_;
};

}  // namespace surfmap
