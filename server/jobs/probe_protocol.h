// The rigs' side of a job: lease a command, answer it with a trace or a
// failure. Every call returns without waiting; its callback runs once the
// answer is durable (on the completion queue), or with the refusal.
//
// Acknowledgements never lie: an OK answer to a trace means this rig's
// samples are stored. The idempotency rule (Store::AcceptTraceAsync): the
// same rig resending the same samples for a command it answered gets
// already_accepted (also after the job ended); other samples, or a rig whose
// lease expired and whose command another rig answered, get ALREADY_EXISTS
// naming the stored trace and its rig; a rig whose lease expired and went to
// another rig that has not answered yet gets FAILED_PRECONDITION. Nothing is
// stored for a refused trace.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "absl/status/statusor.h"
#include "server/estimate/drag_trace.h"
#include "server/estimate/fit_trace.h"
#include "server/jobs/job_executors.h"
#include "server/jobs/job_registry.h"
#include "server/jobs/record_conversion.h"
#include "server/jobs/rig_registrations.h"
#include "storage/store.h"

namespace surfmap {

// The sample as stored (for a retry: what the first submission stored, its
// provenance included), and what else the rig is told.
struct SubmitOutcome : AcceptedSample {
  ProbeCommand probe;
  bool already_accepted = false;
  PlanProgress progress;
  std::optional<LeaseOutcome> next;              // when the submission asked to lease the next command
  std::shared_ptr<const TraceFit> decoded_fit;   // fit.result_json decoded; null for a retry
};

// Why a rig could not measure a command: the plan's FailureKind
// (sampling_plan.h; FailureKind in the API). Unreachable is final at once.

class ProbeProtocol {
 public:
  ProbeProtocol(Store* store, JobRegistry* registry, RigRegistrations* rigs, JobExecutors executors,
                int64_t default_lease_ms);

  using LeaseCallback = std::function<void(absl::StatusOr<LeaseOutcome>)>;
  // job_id 0: any running job. Cheap on the caller's thread (one small read
  // at most); the lease itself is a write.
  void LeaseCommand(const std::string& rig_id, int64_t job_id, LeaseCallback done);

  using SubmitCallback = std::function<void(absl::StatusOr<SubmitOutcome>)>;
  // The frame a submitted trace states (see the second SubmitTrace).
  struct TraceFrameChoice {
    TraceFrame frame = TraceFrame::kObject;
    int64_t registration_id = 0;
  };
  // Makes the trace (e.g. converts it from the request): runs on the pool,
  // since a large trace takes a while. Its errors are the submission's.
  using TraceSource = std::function<absl::StatusOr<DragTrace>()>;
  // Makes and fits the trace on the pool, records it in the plan under the job's lock,
  // queues one write (trace, fit, plan change, new commands and, with
  // lease_next, this rig's next lease) and answers once it is durable.
  // UNAVAILABLE when the pool is full.
  // metadata_json: the trace's provenance (provenance.h), stored with it.
  void SubmitTrace(int64_t command_id, const std::string& rig_id, TraceSource trace, bool lease_next,
                   SubmitCallback done, std::string metadata_json = "{}") {
    SubmitTrace(command_id, rig_id, std::move(trace), lease_next, TraceFrameChoice{}, std::move(done),
                std::move(metadata_json));
  }
  // The frame the trace was sent in (docs/trace-format.md, "Frames"). A trace
  // in a rig's frame is converted to the object's with the rig's registration
  // (registration_id, or 0: the rig's latest for the job's object) before the
  // checks and the fit, and stored as sent with the frame and the
  // registration's id. FAILED_PRECONDITION when the rig has no registration;
  // a registration of another object or rig is INVALID_ARGUMENT. A trace
  // refused because it is in another frame than stated says so ("frame").
  void SubmitTrace(int64_t command_id, const std::string& rig_id, TraceSource trace, bool lease_next,
                   TraceFrameChoice frame, SubmitCallback done, std::string metadata_json = "{}");

  using FailureCallback = std::function<void(absl::StatusOr<bool>)>;  // will the site be retried?
  // Runs on the pool (reads the command, may load the job).
  void ReportFailure(int64_t command_id, const std::string& rig_id, const std::string& reason,
                     FailureKind kind, FailureCallback done);

 private:
  struct CommandContext {
    CommandRecord record;
    ProbeCommand probe;
    std::shared_ptr<JobRuntime> runtime;
  };
  absl::StatusOr<CommandContext> LoadCommandContext(int64_t command_id);
  void FitAndSubmit(int64_t command_id, const std::string& rig_id, const TraceSource& source, bool lease_next,
                    TraceFrameChoice frame, const std::string& metadata_json, SubmitCallback done);
  // The registration a trace in `frame` is read with (null for the object's
  // frame when the rig has none: then nothing can be said about frames).
  absl::StatusOr<std::shared_ptr<const RegisteredRig>> TraceRegistration(const CommandContext& context,
                                                                         const std::string& rig_id,
                                                                         TraceFrameChoice frame) const;
  // What a lease's command in the rig's frame is computed from: the rig's
  // latest registration to the job's object, and the job's surface.
  struct RigFrameSource {
    std::shared_ptr<const LoopSurface> surface;  // null: the site alone
    std::shared_ptr<const RegisteredRig> rig;
  };
  // Nullopt when the lease has no command or the rig is not registered to
  // the job's object (then the answer needs no rig frame). In-memory lookups.
  std::optional<RigFrameSource> RigFrameSourceOf(const LeaseOutcome& outcome, const std::string& rig_id) const;
  // Adds the command in the rig's frame to a lease: traces the commanded drag
  // on the job's surface (centred on the site where the surface allows, 1 mm
  // steps; two or three TraceDragPath calls) for the tool-centre path. Runs
  // on the probes pool, never on the completions thread (which runs every
  // store completion in commit order): a lease answer has no order to keep.
  static void AttachRigFrame(LeaseOutcome& outcome, const RigFrameSource& source);
  // Keeps a trace refused as implausible (out of the map, with an event) and
  // answers the refusal. `trace` is as sent, in `frame` (stored with it).
  void KeepRejected(const CommandContext& context, const std::string& rig_id, const DragTrace& trace,
                    const TraceFrameRecord& frame, const absl::Status& refusal, SubmitCallback done);
  // Under the job's lock: the checks, the plan change and the queued write.
  absl::Status QueueTrace(const CommandContext& context, const std::string& rig_id, const TraceFit& fit,
                          std::vector<StoredSample> samples, bool lease_next, const TraceFrameRecord& frame,
                          const std::string& metadata_json,
                          SubmitCallback& done);
  // A queued trace write, as its completion needs it.
  struct TraceWrite {
    CommandContext context;
    bool plan_changed = false;   // the plan recorded the fit (not a repeated submission)
    bool completes_job = false;  // the write also stores the job as completed
    bool lease_next = false;
    std::shared_ptr<const TraceFit> decoded_fit;
    std::string rig_id;
  };
  // On the completion queue, once the write finished.
  void ApplyAcceptedTrace(const TraceWrite& pending, absl::StatusOr<AcceptTraceResult> result, SubmitCallback done);
  absl::Status QueueFailure(const CommandContext& context, const std::string& rig_id, const std::string& reason,
                            FailureKind kind, FailureCallback& done);

  Store* const store_;
  JobRegistry* const registry_;
  RigRegistrations* const rigs_;
  const JobExecutors executors_;
  const int64_t default_lease_ms_;
};

}  // namespace surfmap
