// Proto <-> domain conversions, with the validation of every field a client
// sends. Proto types end here: nothing below the service sees them.
#pragma once

#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "proto/surfmap/v1/surfmap.pb.h"
#include "server/estimate/drag_trace.h"
#include "server/codec/trace_samples_proto.h"
#include "server/estimate/fit_trace.h"
#include "server/jobs/job_params.h"
#include "storage/records.h"

namespace surfmap {

namespace pb = ::surfmap::v1;

pb::Vec3 ToProto(const Eigen::Vector3d& v);
Eigen::Vector3d FromProto(const pb::Vec3& v);
google::protobuf::Timestamp TimestampFromUnixMs(int64_t unix_ms);

// Appends `more` to `into` column by column (streamed submissions).
void AppendSamples(const pb::TraceSamples& more, pb::TraceSamples* into);

// JobSpec -> JobParams with defaults for zero fields. UNSPECIFIED property or
// mode, unknown enum values, and out-of-range numbers are INVALID_ARGUMENT.
absl::StatusOr<JobParams> JobParamsFromProto(const pb::JobSpec& spec, int64_t default_lease_ms);
pb::JobSpec JobParamsToProto(const JobParams& params);
// Unset fields take TraceLimits' defaults; INVALID_ARGUMENT naming the field.
absl::StatusOr<TraceLimits> TraceLimitsFromProto(const pb::TraceLimits& proto);
absl::StatusOr<Reachability> ReachabilityFromProto(const pb::Reachability& proto);
pb::Reachability ReachabilityToProto(const Reachability& reach);
pb::TraceLimits TraceLimitsToProto(const TraceLimits& limits);

absl::StatusOr<FitOptions> FitOptionsFromProto(const pb::EstimatorSettings& settings);

// result_json -> estimates; `decoded` (when given) is result_json already
// decoded, which spares the JSON on the trace path. DATA_LOSS naming the fit
// when the stored result cannot be read.
absl::StatusOr<pb::Fit> FitToProto(const FitRecord& record, const TraceFit* decoded = nullptr);
// The per-pair mu, its arc lengths, the ACF and the grid step of `fit` (a
// TraceFit computed with the record's options) into `out`.
void AddFitSeries(const TraceFit& fit, double grid_step_mm, pb::Fit* out);
pb::JobState JobStateToProto(JobState state);

}  // namespace surfmap
