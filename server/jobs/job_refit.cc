#include "server/jobs/job_refit.h"

#include <vector>

#include "absl/strings/str_cat.h"
#include "server/base/status_macros.h"
#include "server/jobs/record_conversion.h"
#include "server/jobs/rig_registrations.h"
#include "server/jobs/stored_trace.h"

namespace surfmap {

absl::StatusOr<RefitOutcome> RefitJobTraces(Store& store, const RigRegistrations& rigs, int64_t job_id,
                                            const FitOptions& options, int page_traces) {
  std::string why;
  if (!options.IsValid(&why)) return absl::InvalidArgumentError("estimator settings: " + why);
  RefitOutcome outcome;
  std::vector<TraceRefit> refits;
  int64_t after = 0;
  int traces = 0;
  for (;;) {
    SURFMAP_ASSIGN_OR_RETURN(std::vector<TraceRecord> page,
                             store.ListTracesPage(job_id, after, page_traces, /*include_samples=*/true));
    if (page.empty()) break;
    for (const TraceRecord& trace : page) {
      ++traces;
      after = trace.id;
      // Fits are made in the object's frame (a trace sent in a rig's frame
      // is converted with the registration it was stored with).
      SURFMAP_ASSIGN_OR_RETURN(DragTrace samples,
                               rigs.StoredTraceInObjectFrame(trace.id, FromStoredSamples(trace.samples)));
      absl::StatusOr<TraceFit> fit = FitTrace(samples, options);
      if (!fit.ok()) {
        ++outcome.failed;
        continue;
      }
      refits.push_back(TraceRefit{trace.id, NewFitOf(*fit, options)});
    }
  }
  if (traces == 0) return absl::FailedPreconditionError(absl::StrCat("job ", job_id, " has no traces to refit"));
  if (refits.empty()) return absl::FailedPreconditionError("no trace of the job could be refitted with these settings");
  SURFMAP_ASSIGN_OR_RETURN(std::vector<FitRecord> stored, store.AddFits(refits));
  outcome.refitted = static_cast<int>(stored.size());
  outcome.version = stored.front().version;
  return outcome;
}

}  // namespace surfmap
