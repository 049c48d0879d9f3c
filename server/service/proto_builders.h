// Builds the API's composite messages from domain snapshots (shared by the
// services and the watch stream).
#pragma once

#include <optional>

#include "absl/status/statusor.h"
#include "proto/surfmap/v1/surfmap.pb.h"
#include "server/jobs/job_coordinator.h"
#include "server/jobs/plan_estimate.h"

namespace surfmap {

namespace pb = ::surfmap::v1;

// The plan's counts; `leased` (commands leased with an unexpired lease, from
// the store) is set only when given: callers on the trace path leave it out.
// `leased` (null: not counted) fills JobProgress.leased and each level's.
pb::JobProgress ProgressToProto(const PlanProgress& progress, const LeasedCounts* leased = nullptr);
// The job with its progress (and leased count when the snapshot has one).
pb::JobInfo JobInfoToProto(const JobSnapshot& job);
pb::ObjectInfo ObjectInfoToProto(const ObjectRecord& object);
// `simplified`: the job's control mesh has fewer vertices than the object's mesh.
pb::PlanEstimate PlanEstimateToProto(const PlanEstimate& estimate, bool simplified);

// A sample: the command's site and drag (and the rig that measured it) with
// the trace's fit. `probe` and `decoded_fit`, when given, are
// record.command.command_json and record.fit.result_json already decoded
// (the trace path has them). DATA_LOSS naming the record when the stored
// command or fit cannot be read.
absl::StatusOr<pb::Sample> BuildSample(const SampleRecord& record, const ProbeCommand* probe = nullptr,
                                       const TraceFit* decoded_fit = nullptr);
// A sample of a trace the job accepted (its fit on arrival), as BuildSample
// of its SampleRecord.
absl::StatusOr<pb::Sample> BuildSample(const AcceptedSample& accepted, const ProbeCommand* probe = nullptr,
                                       const TraceFit* decoded_fit = nullptr);
// Samples read from one snapshot (JobReads::ListSamples), appended in order.
absl::Status AppendSamples(const std::vector<SampleRecord>& samples,
                           google::protobuf::RepeatedPtrField<pb::Sample>* out);
// Adds the per-pair mu and the ACF, recomputed from the sample's trace (read
// with its samples) with its fit's options; see JobReads::RecomputeFit.
absl::Status AddRecomputedSeries(JobReads& reads, const SampleRecord& record, pb::Sample* sample);

// Per-vertex values of vertices 0..vertex_count-1 of the finest level (the
// vertices of `level`, by the numbering contract), and the measured samples.
absl::Status FillMapLevel(const MapSnapshot& snapshot, int level, const std::vector<SampleRecord>& samples,
                          int64_t job_id, pb::MapLevel* out);
void FillMesh(const SurfaceLevel& level, int level_index, int64_t object_id, pb::GetMeshResponse* out);

}  // namespace surfmap
