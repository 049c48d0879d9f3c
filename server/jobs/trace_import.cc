#include "server/jobs/trace_import.h"

#include <algorithm>
#include <utility>

#include <openssl/sha.h>
#include <nlohmann/json.hpp>
#include <spdlog/spdlog.h>
#include "absl/strings/str_cat.h"
#include "server/base/status_macros.h"
#include "server/base/utf8_text.h"
#include "server/estimate/line_sample.h"
#include "server/estimate/trace_csv.h"
#include "server/jobs/command_json.h"
#include "server/jobs/import_locate.h"
#include "server/jobs/job_watchers.h"
#include "server/jobs/plan_write.h"
#include "server/jobs/record_conversion.h"
#include "server/jobs/stored_trace.h"
#include "server/jobs/trace_plausibility.h"
#include "server/plan/plan_journal.h"

namespace surfmap {
namespace {

// The name a refusal gives the import by: its file, or its source.
std::string ImportName(const TraceImportRequest& request) {
  return request.file_name.empty() ? absl::StrCat("trace from '", request.source, "'")
                                   : absl::StrCat("trace '", request.file_name, "' from '", request.source, "'");
}

NewCommand ImpliedCommandRecord(const ProbeCommand& implied) {
  return NewCommand{implied.site.level, implied.site.vertex, ProbeCommandToJson(implied)};
}

}  // namespace

absl::Status ValidateTraceImportRequest(const TraceImportRequest& r) {
  if (r.job_id <= 0) return absl::InvalidArgumentError("job_id must be a positive job id");
  SURFMAP_RETURN_IF_ERROR(ValidateName("source", r.source, 1, 100));
  SURFMAP_RETURN_IF_ERROR(ValidateName("file_name", r.file_name, 0, 500));
  if (r.recorded_unix_ms < 0) return absl::InvalidArgumentError("recorded time must not be before 1970");
  return ValidateProvenance(r.provenance);
}

std::string ImportMetadataJson(const TraceImportRequest& r) {
  nlohmann::json j = {{"import",
                       {{"source", r.source},
                        {"file_name", r.file_name},
                        {"file_sha256", r.file_sha256},
                        {"recorded_unix_ms", r.recorded_unix_ms}}}};
  if (!r.provenance.empty()) j["provenance"] = ProvenanceToJson(r.provenance);
  return j.dump();
}

std::string Sha256Hex(std::string_view bytes) {
  unsigned char digest[SHA256_DIGEST_LENGTH];
  SHA256(reinterpret_cast<const unsigned char*>(bytes.data()), bytes.size(), digest);
  static constexpr char kHex[] = "0123456789abcdef";
  std::string hex;
  hex.reserve(2 * SHA256_DIGEST_LENGTH);
  for (unsigned char b : digest) {
    hex.push_back(kHex[b >> 4]);
    hex.push_back(kHex[b & 15]);
  }
  return hex;
}

absl::Status CheckCsvSize(std::string_view csv, int max_samples) {
  // Blank lines are skipped by the reader (docs/trace-format.md), so they do
  // not count: a double-spaced file of max_samples rows is within the limit.
  int64_t lines = 0;
  bool blank = true;  // the current line so far holds only blanks
  for (char c : csv) {
    if (c == '\n') {
      lines += !blank;
      blank = true;
    } else if (c != ' ' && c != '\t' && c != '\r') {
      blank = false;
    }
  }
  lines += !blank;
  const int64_t limit = static_cast<int64_t>(max_samples) + 101;  // + header + comment lines
  if (lines > limit) {
    return absl::ResourceExhaustedError(absl::StrCat("trace CSV has ", lines, " non-blank lines; the limit is ", limit, " (",
                                                     max_samples, " samples per trace, max_trace_samples, + header "
                                                     "and 100 comment lines)"));
  }
  return absl::OkStatus();
}

TraceImporter::TraceImporter(Store* store, JobRegistry* registry, JobExecutors executors)
    : store_(store), registry_(registry), executors_(executors) {}

void TraceImporter::Import(TraceImportRequest request, std::shared_ptr<const std::string> csv, int max_samples,
                           Callback done) {
  if (absl::Status s = ValidateTraceImportRequest(request); !s.ok()) return done(s);
  if (csv == nullptr || csv->empty()) return done(absl::InvalidArgumentError("csv is empty (0 bytes)"));
  SubmitImport(std::move(request), std::move(csv), max_samples, /*may_wait=*/true, std::move(done));
}

void TraceImporter::SubmitImport(TraceImportRequest request, std::shared_ptr<const std::string> csv, int max_samples,
                                 bool may_wait, Callback done) {
  auto shared_done = std::make_shared<Callback>(std::move(done));
  const bool queued = executors_.probes->Submit(
      [this, request = std::move(request), csv = std::move(csv), max_samples, may_wait, shared_done]() mutable {
        LocateFitAndQueue(std::move(request), std::move(csv), max_samples, may_wait, std::move(*shared_done));
      });
  if (!queued) (*shared_done)(absl::UnavailableError("server busy: work queue full, retry the import later"));
}

void TraceImporter::AnswerStored(int64_t trace_id, Callback done) {
  absl::StatusOr<SampleRecord> stored = store_->ReadSample(trace_id, 1, /*include_samples=*/false);
  if (!stored.ok()) return done(stored.status());
  absl::StatusOr<ProbeCommand> probe = ProbeCommandFromJson(stored->command.command_json);
  if (!probe.ok()) {
    return done(absl::DataLossError(absl::StrCat("stored command ", stored->command.id,
                                                 " cannot be read: ", probe.status().message())));
  }
  TraceImportOutcome outcome;
  outcome.command = std::move(stored->command);
  outcome.probe = std::move(*probe);
  outcome.trace_id = trace_id;
  outcome.fit = std::move(stored->fit);
  outcome.received_unix_ms = stored->trace.received_unix_ms;
  outcome.metadata_json = std::move(stored->trace.metadata_json);
  outcome.already_imported = true;
  done(std::move(outcome));
}

void TraceImporter::LocateFitAndQueue(TraceImportRequest request, std::shared_ptr<const std::string> csv_bytes,
                                      int max_samples, bool may_wait, Callback done) {
  const std::string& csv = *csv_bytes;
  request.file_sha256 = Sha256Hex(csv);
  // The same file again: the stored import, before any work (one indexed read).
  absl::StatusOr<int64_t> stored = store_->FindImportedTrace(request.job_id, request.file_sha256);
  if (!stored.ok()) return done(stored.status());
  if (*stored != 0) return AnswerStored(*stored, std::move(done));

  // A finished job takes nothing, refused or not: say so before any work (and
  // before a refusal would be kept in it).
  absl::StatusOr<std::shared_ptr<JobRuntime>> runtime = registry_->Get(request.job_id);
  if (!runtime.ok()) return done(runtime.status());
  {
    MutexLock lock(&(*runtime)->mu);
    if ((*runtime)->needs_reload && may_wait) {
      // An import is an operator's call, like a pause or a cancel: it waits
      // out the job's re-read after a failed write (before any work, since
      // the job's state is not known until then) instead of being told to
      // retry. Once: a second re-read is answered UNAVAILABLE.
      registry_->DeferUntilReloadedLocked(
          **runtime, [this, request, csv_bytes, max_samples, done = std::move(done)](absl::Status reloaded) mutable {
            if (!reloaded.ok()) return done(reloaded);
            SubmitImport(std::move(request), std::move(csv_bytes), max_samples, /*may_wait=*/false, std::move(done));
          });
      return;
    }
    if (absl::Status takes = registry_->CheckTakesAnswersLocked(**runtime, "traces, imported or not"); !takes.ok()) {
      return done(takes);
    }
  }
  if (absl::Status bounded = CheckCsvSize(csv, max_samples); !bounded.ok()) return done(bounded);
  absl::StatusOr<DragTrace> made =
      ParseTraceCsv(csv, request.file_name.empty() ? std::string_view("import") : std::string_view(request.file_name));
  if (!made.ok()) return done(made.status());
  const DragTrace trace = std::move(*made);
  if (trace.samples.size() > static_cast<size_t>(max_samples)) {
    return done(absl::ResourceExhaustedError(absl::StrCat("trace CSV has ", trace.samples.size(),
                                                          " samples; the limit is ", max_samples,
                                                          " (max_trace_samples)")));
  }
  const JobParams& params = (*runtime)->params;
  auto refused = [&](const absl::Status& s) {
    return absl::Status(s.code(), absl::StrCat(ImportName(request), ": ", s.message()));
  };

  absl::StatusOr<LocatedDrag> located = LocateImportedDrag(trace, *(*runtime)->surface, params.probe);
  if (!located.ok()) return done(refused(located.status()));
  const ProbeCommand& implied = located->command;
  // The same checks as a leased trace's, against the command the path
  // implies: the cheap ones first (one pass; a malformed trace is refused as
  // such), then the surface distance (a closest-point query per sample).
  absl::Status plausible = CheckTraceAgainstCommand(trace, implied, params.limits);
  if (plausible.ok()) {
    const SurfaceDistance farthest = FarthestFromSurface(trace, *(*runtime)->surface);
    plausible = CheckTraceNearSurface(farthest.max_mm, farthest.sample, params.limits);
  }
  if (!plausible.ok()) {
    if (PlausibilityCheckName(plausible).empty()) return done(refused(plausible));  // malformed: nothing to keep
    return KeepRejected(request, *runtime, implied, trace, plausible, std::move(done));
  }
  absl::StatusOr<TraceFit> fitted = FitTrace(trace, params.fit);
  if (!fitted.ok()) return done(refused(fitted.status()));
  if (absl::Status s = CheckFitAgainstCommand(trace, *fitted, implied, params.limits); !s.ok()) {
    return KeepRejected(request, *runtime, implied, trace, s, std::move(done));
  }
  absl::Status queued = QueueImport(request, *runtime, implied, *fitted, trace, done);
  if (!queued.ok()) done(refused(queued));  // after the job's lock is released
}

void TraceImporter::KeepRejected(const TraceImportRequest& request, const std::shared_ptr<JobRuntime>& runtime,
                                 const ProbeCommand& implied, const DragTrace& trace, const absl::Status& refusal,
                                 Callback done) {
  NewRejectedTrace rejected;
  rejected.job_id = request.job_id;
  rejected.rig_id = request.source;
  rejected.implied_command = ImpliedCommandRecord(implied);
  rejected.check_name = PlausibilityCheckName(refusal);
  rejected.message = absl::StrCat(ImportName(request), ": ", refusal.message());
  rejected.encoded_samples = EncodeSamples(ToStoredSamples(trace));
  rejected.import_sha256 = request.file_sha256;  // the same file refused again writes nothing
  rejected.events.push_back(Event("import_rejected", {{"source", request.source},
                                                      {"file_name", request.file_name},
                                                      {"file_sha256", request.file_sha256},
                                                      {"check", rejected.check_name},
                                                      {"message", rejected.message}}));
  const absl::Status answer(refusal.code(), absl::StrCat(ImportName(request), " refused (kept for inspection, not "
                                                         "in the map): ", refusal.message()));
  store_->RecordRejectedTraceAsync(std::move(rejected), [this, runtime, answer, done = std::move(done)](
                                                            absl::StatusOr<int64_t> kept) mutable {
    executors_.completions->Post([runtime, answer, kept, done = std::move(done)]() mutable {
      NotifyListeners(*runtime);
      done(kept.ok() ? answer : absl::Status(answer.code(), absl::StrCat(answer.message(), " (keeping it failed: ",
                                                                          kept.status().message(), ")")));
    });
  });
}

absl::Status TraceImporter::QueueImport(const TraceImportRequest& request, const std::shared_ptr<JobRuntime>& runtime_ptr,
                                        const ProbeCommand& implied, const TraceFit& fit, const DragTrace& trace,
                                        Callback& done) {
  JobRuntime& runtime = *runtime_ptr;
  AcceptTraceRequest write;
  write.job_id = request.job_id;
  write.encoded_samples = EncodeSamples(ToStoredSamples(trace));  // O(samples): before the lock
  write.metadata_json = ImportMetadataJson(request);
  write.import = TraceImport{ImpliedCommandRecord(implied), request.source, request.file_sha256};
  CommandRecord command;  // as the write stores it; the id comes with the result
  command.job_id = request.job_id;
  command.site_level = implied.site.level;
  command.site_vertex = implied.site.vertex;
  command.command_json = write.import->command.command_json;
  command.state = CommandState::kDone;
  command.lease_owner = request.source;
  command.attempt = 1;
  bool completes_job = false;
  const int keep_issued = registry_->lookahead().CommandsAhead(UnixMillisNow());
  {
    MutexLock lock(&runtime.mu);
    SURFMAP_RETURN_IF_ERROR(registry_->CheckTakesAnswersLocked(runtime, "traces, imported or not"));
    if (runtime.importing_sha256.count(request.file_sha256) > 0) {
      // As QueueTrace answers for a leased trace: before the plan changes.
      return absl::UnavailableError("the same file is being stored; retry the import (it then answers "
                                    "already_imported)");
    }
    PlanJournalEntry entry;
    entry.kind = PlanJournalEntry::Kind::kImport;
    entry.line = LineSampleOf(fit);
    entry.position = implied.position;
    SURFMAP_RETURN_IF_ERROR(ApplyPlanJournalEntry(entry, runtime.plan));
    PlanWrite plan_write = TakePlanChangeLocked(runtime, entry, keep_issued);
    completes_job = plan_write.new_job_state.has_value();
    std::move(plan_write).MoveInto(write);
    runtime.importing_sha256.insert(request.file_sha256);  // until the write's completion
    runtime.measured_revision++;
    write.fit = NewFitOf(fit, runtime.params.fit);
    write.events.push_back(Event("trace_imported", {{"source", request.source},
                                                    {"file_name", request.file_name},
                                                    {"file_sha256", request.file_sha256},
                                                    {"vertex", implied.site.vertex},
                                                    {"mu", fit.friction.mu}}));
    // Queued under the lock: writes of one job commit in the order their plan changes were made.
    auto decoded = std::make_shared<const TraceFit>(fit);
    store_->AcceptTraceAsync(
        std::move(write), [this, runtime_ptr, command, implied, decoded, completes_job, sha256 = request.file_sha256,
                           done = std::move(done)](absl::StatusOr<AcceptTraceResult> result) mutable {
          executors_.completions->Post([this, runtime_ptr, command, implied, decoded, completes_job,
                                        sha256 = std::move(sha256), result = std::move(result),
                                        done = std::move(done)]() mutable {
            JobRuntime& runtime = *runtime_ptr;
            {
              MutexLock lock(&runtime.mu);
              runtime.importing_sha256.erase(sha256);
            }
            if (!result.ok()) return done(registry_->MarkWriteFailed(runtime, result.status()));
            if (result->already_accepted) {
              // Backstop (importing_sha256 keeps this from happening within
              // one server): the file was stored by another writer; memory
              // recorded this one too, the database did not, so the job is
              // reloaded. The answer is the stored import, from the result
              // (no read on this queue).
              (void)registry_->MarkWriteFailed(runtime, absl::OkStatus());
            }
            if (!result->fit.has_value()) {
              return done(absl::DataLossError(absl::StrCat("trace ", result->trace_id, " was stored without its fit")));
            }
            TraceImportOutcome outcome;
            outcome.command = command;
            outcome.command.id = result->command_id;
            outcome.probe = implied;
            outcome.trace_id = result->trace_id;
            outcome.fit = *result->fit;
            outcome.received_unix_ms = result->accepted_unix_ms;
            outcome.metadata_json = std::move(result->metadata_json);
            if (result->already_accepted) {
              outcome.already_imported = true;
              return done(std::move(outcome));
            }
            outcome.decoded_fit = decoded;
            bool finished = false;
            {
              MutexLock lock(&runtime.mu);
              runtime.latest_sample =
                  std::make_shared<AcceptedSample>(static_cast<const AcceptedSample&>(outcome));
              runtime.updated_unix_ms = std::max(runtime.updated_unix_ms, outcome.received_unix_ms);
              if (completes_job) runtime.durable_state = JobState::kCompleted;
              finished = IsFinalJobState(runtime.durable_state);
            }
            if (finished) registry_->NoteFinished(runtime.job_id);
            spdlog::info("trace imported job_id={} trace_id={} vertex={}", runtime.job_id, outcome.trace_id,
                         outcome.command.site_vertex);
            NotifyListeners(runtime);
            done(std::move(outcome));
          });
        });
  }
  return absl::OkStatus();
}

}  // namespace surfmap
