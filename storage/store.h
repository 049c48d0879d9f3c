// Store: the persistence interface the service uses. SqliteStore
// (sqlite_store.h) is the implementation; another backend implements this same
// interface without the service changing.
//
// Contract for every implementation:
// - Thread-safe: any method may be called from any thread concurrently.
// - Never throws. Errors: NotFound for an unknown id (the message names it),
//   InvalidArgument for a malformed input (names the field), FailedPrecondition
//   for a call that is wrong in the current state, Aborted for a lost
//   optimistic-concurrency race (retry after re-reading), Unavailable for a
//   retry-able backend failure (busy, I/O, disk full), Internal otherwise.
// - A write that returns OK (or whose callback receives OK) is durable: it
//   survives a crash of the process and, per the backend's guarantees, power
//   loss. A write that fails has written nothing.
// - Reads see every write that completed before the read started.
// - Asynchronous writes run in the order they were submitted; their
//   callbacks run in that order too, on one thread of the store's (or, for a
//   request rejected before queuing, on the caller's thread before the call
//   returns). A callback must not block and must not take a lock a caller of
//   the store may hold: callers post the work to their own executor.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <vector>

#include "absl/status/statusor.h"
#include "storage/records.h"

namespace surfmap {

class Store {
 public:
  using AcceptTraceCallback = std::function<void(absl::StatusOr<AcceptTraceResult>)>;
  using LeaseCallback = std::function<void(absl::StatusOr<std::optional<CommandRecord>>)>;

  virtual ~Store() = default;

  // ---- Objects ----
  // mesh_format must be "obj" or "ply", mesh_bytes non-empty. Returns the id.
  virtual absl::StatusOr<int64_t> CreateObject(const NewObject& object) = 0;
  virtual absl::StatusOr<ObjectRecord> GetObject(int64_t object_id, bool include_mesh) = 0;
  // Oldest first, without mesh bytes.
  virtual absl::StatusOr<std::vector<ObjectRecord>> ListObjects() = 0;

  // ---- Jobs and plans ----
  // One transaction: the job (state running), its plan (revision 1), its
  // commands (pending) and events. NotFound if the object does not exist.
  virtual absl::StatusOr<CreatedJob> CreateJob(const NewJob& job) = 0;
  virtual absl::StatusOr<JobRecord> GetJob(int64_t job_id) = 0;
  // object_id 0: all jobs. Oldest first.
  virtual absl::StatusOr<std::vector<JobRecord>> ListJobs(int64_t object_id) = 0;
  // The jobs still running or paused, oldest first (what a restart resumes).
  virtual absl::StatusOr<std::vector<JobRecord>> ListActiveJobs() = 0;
  // FailedPrecondition if the transition is not allowed (IsJobTransitionAllowed)
  // from the stored state when the write runs. The callback runs once durable.
  using JobCallback = std::function<void(absl::StatusOr<JobRecord>)>;
  virtual void UpdateJobStateAsync(JobStateChange change, JobCallback done) = 0;
  // Blocks until durable.
  absl::StatusOr<JobRecord> UpdateJobState(JobStateChange change);
  virtual absl::StatusOr<PlanRecord> GetPlan(int64_t job_id) = 0;

  // ---- Commands ----
  // Atomically leases the oldest command of a running job (request.job_id, or
  // any job if 0) that is pending or whose lease has expired (deadline <= now):
  // a command is never held by two rigs at once. nullopt if there is none.
  // The callback runs on the store's writer thread once the lease is durable;
  // it must not block.
  virtual void LeaseNextCommandAsync(const LeaseRequest& request, LeaseCallback done) = 0;
  absl::StatusOr<std::optional<CommandRecord>> LeaseNextCommand(const LeaseRequest& request);
  virtual absl::StatusOr<CommandRecord> GetCommand(int64_t command_id) = 0;
  // In id order.
  virtual absl::StatusOr<std::vector<CommandRecord>> ListCommands(int64_t job_id) = 0;
  // Commands of the job leased with a lease still valid at now_unix_ms
  // (deadline > now: the rule LeaseNextCommand uses), in all and per site
  // level. NotFound for an unknown job.
  virtual absl::StatusOr<LeasedCounts> CountLeasedCommands(int64_t job_id, int64_t now_unix_ms) = 0;

  // ---- Traces ----
  // One atomic, durable write: the trace, its fit (version 1), the command set
  // to done, the new plan state, new commands, the job state change, events.
  // A command takes one trace. When it already has one:
  //   - from the same rig (lease_owner) with the same samples: a retry after
  //     a lost reply; OK with already_accepted, whatever the job's state now;
  //   - with other samples, or from another rig (whose lease expired and the
  //     command went to that rig, which answered): AlreadyExists, naming the
  //     stored trace and its rig; nothing is written.
  // Otherwise FailedPrecondition if the command is not leased (or leased by
  // another owner when request.lease_owner is set, saying when the old lease
  // expired), or its job is cancelled/completed.
  // The callback runs on the store's writer thread once the write is durable
  // (or has failed); it must not block.
  virtual void AcceptTraceAsync(AcceptTraceRequest request, AcceptTraceCallback done) = 0;
  // Blocks until durable.
  absl::StatusOr<AcceptTraceResult> AcceptTrace(AcceptTraceRequest request);
  // A leased command that could not be measured, with the plan's reaction,
  // in one durable write. FailedPrecondition if the command is not leased (by
  // request.lease_owner when set) or its job is cancelled/completed; Aborted on
  // a plan revision mismatch. The callback runs on the writer thread.
  using FailCommandCallback = std::function<void(absl::StatusOr<FailCommandResult>)>;
  virtual void FailCommandAsync(FailCommandRequest request, FailCommandCallback done) = 0;
  virtual absl::StatusOr<TraceRecord> GetTrace(int64_t trace_id, bool include_samples) = 0;
  // In id order (= order of acceptance).
  virtual absl::StatusOr<std::vector<TraceRecord>> ListTraces(int64_t job_id,
                                                              bool include_samples) = 0;
  // At most `limit` (> 0) of the job's traces with id > after_trace_id, in id
  // order: for reading every trace with its samples in bounded memory.
  virtual absl::StatusOr<std::vector<TraceRecord>> ListTracesPage(int64_t job_id, int64_t after_trace_id, int limit,
                                                                  bool include_samples) = 0;
  // The trace imported into the job from the file with this SHA-256 (see
  // TraceImport), if any: one indexed lookup. 0 when there is none.
  virtual absl::StatusOr<int64_t> FindImportedTrace(int64_t job_id, const std::string& sha256) = 0;
  // The job's newest trace and newest event time (two indexed lookups).
  // NotFound for an unknown job.
  virtual absl::StatusOr<JobActivity> GetJobActivity(int64_t job_id) = 0;

  // ---- Fits ----
  // version 0: the latest version for the trace.
  virtual absl::StatusOr<FitRecord> GetFit(int64_t trace_id, int32_t version) = 0;
  // A refit, in one transaction: every fit of the batch gets the same version,
  // one more than the highest version stored for any trace of the batch.
  // Each trace at most once per batch. Returns the records in input order.
  virtual absl::StatusOr<std::vector<FitRecord>> AddFits(const std::vector<TraceRefit>& fits) = 0;
  // The job's fits of one version, or with version 0 the latest fit of each
  // trace; in trace order.
  virtual absl::StatusOr<std::vector<FitRecord>> ListFits(int64_t job_id, int32_t version) = 0;

  // ---- Rejected traces ----
  // Keeps a refused trace with its events, at most kMaxRejectedPerCommand per
  // command (later ones are counted in the events only). The callback gets
  // the id, or 0 when the command's quota was used up. A refused import is
  // kept once per file (import_sha256) and job: the same file again writes
  // nothing and gets the stored one's id.
  static constexpr int kMaxRejectedPerCommand = 3;
  using RejectedCallback = std::function<void(absl::StatusOr<int64_t>)>;
  virtual void RecordRejectedTraceAsync(NewRejectedTrace trace, RejectedCallback done) = 0;
  // Oldest first; NotFound for an unknown job.
  virtual absl::StatusOr<std::vector<RejectedTraceRecord>> ListRejectedTraces(int64_t job_id) = 0;
  virtual absl::StatusOr<RejectedTraceRecord> GetRejectedTrace(int64_t id) = 0;

  // ---- Samples: a trace, its command and a fit, from one snapshot ----
  // fit_version 0 = the latest fit. NotFound for an unknown trace or fit.
  virtual absl::StatusOr<SampleRecord> ReadSample(int64_t trace_id, int32_t fit_version, bool include_samples) = 0;
  // Every trace of the job with its command and its fit of `fit_version` (0 =
  // latest; traces without a fit of that version are left out), in trace
  // order, without samples, all from one snapshot. NotFound for an unknown job.
  virtual absl::StatusOr<std::vector<SampleRecord>> ReadJobSamples(int64_t job_id, int32_t fit_version) = 0;

  // ---- Rig registrations (append-only versions per object and rig) ----
  // Stores the next version for (object_id, rig_name). NotFound for an
  // unknown object; InvalidArgument for an empty rig name or invalid JSON.
  virtual absl::StatusOr<RigRegistrationRecord> AddRigRegistration(const NewRigRegistration& registration) = 0;
  virtual absl::StatusOr<RigRegistrationRecord> GetRigRegistration(int64_t registration_id) = 0;
  // Every version, oldest first; object_id 0: every object's.
  virtual absl::StatusOr<std::vector<RigRegistrationRecord>> ListRigRegistrations(int64_t object_id) = 0;
  // The frame the trace was sent in ("object" when it was sent in the
  // object's frame). NotFound for an unknown trace.
  virtual absl::StatusOr<TraceFrameRecord> GetTraceFrame(int64_t trace_id) = 0;

  // ---- Ordering ----
  // `done` runs once every write submitted before this call has completed
  // (a barrier through the write queue; writes nothing).
  virtual void SyncAsync(std::function<void(absl::Status)> done) = 0;

  // ---- Events ----
  // Events with id > after_id, oldest first, at most limit (> 0). job_id 0: all.
  virtual absl::StatusOr<std::vector<EventRecord>> ListEvents(int64_t job_id, int64_t after_id,
                                                              int limit) = 0;
  // Events with id < before_id (0: no bound), newest first, at most limit
  // (> 0): the end of a long job's history without reading all of it.
  virtual absl::StatusOr<std::vector<EventRecord>> ListEventsNewestFirst(int64_t job_id, int64_t before_id,
                                                                         int limit) = 0;
};

}  // namespace surfmap
