// What the service reads besides the jobs' live state: objects, samples and
// traces, straight from the store. Each call is one read, and a job's samples
// come from one snapshot, so a trace is never shown without its command or
// fit. Reads with samples are bulk reads (pool threads).
#pragma once

#include <cstdint>
#include <vector>

#include "absl/status/statusor.h"
#include "server/estimate/fit_trace.h"
#include "server/jobs/rig_registrations.h"
#include "storage/store.h"

namespace surfmap {

class JobReads {
 public:
  // `rigs`: converts traces sent in a rig's frame (RecomputeFit).
  JobReads(Store* store, const RigRegistrations* rigs) : store_(store), rigs_(rigs) {}

  absl::StatusOr<ObjectRecord> GetObject(int64_t object_id) { return store_->GetObject(object_id, false); }
  absl::StatusOr<std::vector<ObjectRecord>> ListObjects() { return store_->ListObjects(); }
  // The frame a trace was sent in (frames and calibration).
  absl::StatusOr<TraceFrameRecord> GetTraceFrame(int64_t trace_id) { return store_->GetTraceFrame(trace_id); }

  // fit_version 0 = latest.
  absl::StatusOr<SampleRecord> GetSample(int64_t trace_id, int32_t fit_version, bool include_samples) {
    return store_->ReadSample(trace_id, fit_version, include_samples);
  }
  absl::StatusOr<std::vector<SampleRecord>> ListSamples(int64_t job_id, int32_t fit_version) {
    return store_->ReadJobSamples(job_id, fit_version);
  }
  absl::StatusOr<TraceRecord> GetTrace(int64_t trace_id) { return store_->GetTrace(trace_id, true); }
  absl::StatusOr<std::vector<RejectedTraceRecord>> ListRejectedTraces(int64_t job_id) {
    return store_->ListRejectedTraces(job_id);
  }
  absl::StatusOr<RejectedTraceRecord> GetRejectedTrace(int64_t id) { return store_->GetRejectedTrace(id); }
  // The job's events with id > after_id, oldest first, at most `limit`.
  absl::StatusOr<std::vector<EventRecord>> ListEventsNewestFirst(int64_t job_id, int64_t before_id, int limit) {
    return store_->ListEventsNewestFirst(job_id, before_id, limit);
  }
  absl::StatusOr<std::vector<EventRecord>> ListEvents(int64_t job_id, int64_t after_id, int limit) {
    return store_->ListEvents(job_id, after_id, limit);
  }

  // Refits a sample read with its samples using its fit's own options, for
  // the per-pair series and the ACF. DATA_LOSS if the stored options cannot
  // be read or the refit does not reproduce the stored mu (the estimator is
  // deterministic). Long work for a large trace: a pool thread.
  // A trace sent in a rig's frame is converted first, with its registration.
  absl::StatusOr<TraceFit> RecomputeFit(const SampleRecord& sample, FitOptions* options);

 private:
  Store* const store_;
  const RigRegistrations* const rigs_;
};

}  // namespace surfmap
