#include "server/jobs/job_reads.h"

#include <cmath>

#include <nlohmann/json.hpp>
#include "absl/strings/str_cat.h"
#include "server/codec/fit_json.h"
#include "server/jobs/rig_registrations.h"
#include "server/jobs/stored_trace.h"

namespace surfmap {

absl::StatusOr<TraceFit> JobReads::RecomputeFit(const SampleRecord& sample, FitOptions* options) {
  const FitRecord& record = sample.fit;
  const nlohmann::json options_json = nlohmann::json::parse(record.options_json, nullptr, false);
  absl::StatusOr<FitOptions> parsed = options_json.is_discarded()
                                          ? absl::DataLossError("stored fit options are not JSON")
                                          : FitOptionsFromJson(options_json);
  if (!parsed.ok()) {
    return absl::DataLossError(absl::StrCat("fit ", record.id, ": stored options: ", parsed.status().message()));
  }
  // The fit was made in the object's frame: a trace sent in a rig's frame is
  // converted with the registration it was stored with.
  absl::StatusOr<DragTrace> trace =
      rigs_->StoredTraceInObjectFrame(sample.trace.id, FromStoredSamples(sample.trace.samples));
  if (!trace.ok()) return trace.status();
  absl::StatusOr<TraceFit> fit = FitTrace(*trace, *parsed);
  if (!fit.ok()) {
    return absl::DataLossError(absl::StrCat("trace ", sample.trace.id, " no longer fits: ", fit.status().message()));
  }
  // Bit-equal with the build that stored the fit; a later build may round
  // differently in the last digits, never more.
  if (record.mu.has_value() && !(std::abs(fit->friction.mu - *record.mu) <= 1e-9)) {
    return absl::DataLossError(absl::StrCat("trace ", sample.trace.id, ": refit mu ", fit->friction.mu,
                                            " differs from the stored ", *record.mu, " (fit by estimator ",
                                            record.estimator_version, ")"));
  }
  *options = *parsed;
  return fit;
}

}  // namespace surfmap
