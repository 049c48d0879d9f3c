#include "server/jobs/record_conversion.h"

#include <chrono>
#include <limits>

#include "absl/strings/str_cat.h"
#include "server/codec/fit_json.h"
#include "server/jobs/command_json.h"

namespace surfmap {
namespace {

// How long a rig that found nothing to lease waits before asking again:
// short against a drag (seconds), long against a lease round trip (~1 ms).
constexpr int64_t kRetryAfterMs = 200;

}  // namespace

int64_t UnixMillisNow() {
  return std::chrono::duration_cast<std::chrono::milliseconds>(std::chrono::system_clock::now().time_since_epoch())
      .count();
}

NewFit NewFitOf(const TraceFit& fit, const FitOptions& options) {
  NewFit f;
  f.estimator_name = kEstimatorName;
  f.estimator_version = kEstimatorVersion;
  f.options_json = FitOptionsToJson(options).dump();
  f.result_json = TraceFitToJson(fit).dump();
  f.mu = fit.friction.mu;
  if (fit.roughness.a.size() > 0) f.a1 = fit.roughness.a[0];
  if (fit.roughness.a.size() > 1) f.a2 = fit.roughness.a[1];
  f.sigma = fit.roughness.sigma;
  return f;
}

std::vector<NewCommand> DrainCommands(SamplingPlan& plan, int keep_issued) {
  std::vector<NewCommand> out;
  if (!plan.DecidesAtIssue()) keep_issued = std::numeric_limits<int>::max();
  while (plan.OutstandingCount() < keep_issued) {
    std::optional<ProbeCommand> c = plan.NextCommand();
    if (!c) break;
    out.push_back(NewCommand{c->site.level, c->site.vertex, ProbeCommandToJson(*c)});
  }
  return out;
}

NewEvent Event(const std::string& kind, const nlohmann::json& detail) { return NewEvent{kind, detail.dump()}; }

absl::StatusOr<LeaseOutcome> LeaseOutcomeOf(std::optional<CommandRecord> leased) {
  LeaseOutcome outcome;
  if (!leased.has_value()) {
    outcome.retry_after_ms = kRetryAfterMs;
    return outcome;
  }
  absl::StatusOr<ProbeCommand> probe = ProbeCommandFromJson(leased->command_json);
  if (!probe.ok()) {
    return absl::DataLossError(
        absl::StrCat("stored command ", leased->id, " cannot be read: ", probe.status().message()));
  }
  probe->attempt = leased->attempt;
  outcome.record = std::move(*leased);
  outcome.command = *probe;
  return outcome;
}

}  // namespace surfmap
