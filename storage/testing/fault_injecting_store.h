// FaultInjectingStore: a Store that forwards every call to another Store and
// can make chosen writes fail, wait or be held, and can deliver write
// callbacks on the caller's thread (inline) or late from a thread of its own,
// after LevelDB's EnvWrapper / fault-injection environment. Tests of the
// layers above use it to check that nothing waits on storage while holding a
// lock, that a failed write leaves memory and database agreeing, and that
// callbacks arriving early, late or inline cannot deadlock.
//
// Writes are numbered from 1 in the order they are submitted (every write
// method, blocking or asynchronous, and SyncAsync). They reach the wrapped
// store in that same order: a held or delayed write holds back every later
// write, as a slow disk would.
#pragma once

#include <cstdint>
#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <thread>

#include "absl/base/thread_annotations.h"
#include "absl/status/status.h"
#include "server/base/mutex.h"
#include "absl/time/time.h"
#include "server/base/task_queue.h"
#include "storage/store.h"

namespace surfmap {

class FaultInjectingStore : public Store {
 public:
  enum class CallbackDelivery {
    kAsWrapped,  // as the wrapped store calls it (its writer thread)
    kLate,       // from this store's own thread, after `late_by`
    kInline,     // on the calling thread, before the call returns (the call
                 // waits for the wrapped store: holds and delays still apply)
  };

  explicit FaultInjectingStore(Store* wrapped);
  // Releases every hold and delivers every outstanding callback.
  ~FaultInjectingStore() override;

  // Write n fails with `status` without reaching the wrapped store.
  void FailWrite(int64_t n, absl::Status status) ABSL_LOCKS_EXCLUDED(mu_);
  // Every write from n on fails with `status` (a broken disk), until
  // HealWrites().
  void FailWritesFrom(int64_t n, absl::Status status) ABSL_LOCKS_EXCLUDED(mu_);
  void HealWrites() ABSL_LOCKS_EXCLUDED(mu_);
  // Write n reaches the wrapped store `delay` after it was submitted.
  void DelayWrite(int64_t n, absl::Duration delay) ABSL_LOCKS_EXCLUDED(mu_);
  // Write n waits (and every later write behind it) until ReleaseWrite(n).
  void HoldWrite(int64_t n) ABSL_LOCKS_EXCLUDED(mu_);
  void ReleaseWrite(int64_t n) ABSL_LOCKS_EXCLUDED(mu_);
  // True once write n was submitted and is being held (false after `timeout`).
  bool WaitUntilHeld(int64_t n, absl::Duration timeout) ABSL_LOCKS_EXCLUDED(mu_);
  void SetCallbackDelivery(CallbackDelivery delivery, absl::Duration late_by = absl::ZeroDuration())
      ABSL_LOCKS_EXCLUDED(mu_);
  // Writes submitted so far (the number the next one gets, minus one).
  int64_t writes_submitted() const ABSL_LOCKS_EXCLUDED(mu_);

  // ---- Store ----
  absl::StatusOr<int64_t> CreateObject(const NewObject& object) override;
  absl::StatusOr<ObjectRecord> GetObject(int64_t object_id, bool include_mesh) override;
  absl::StatusOr<std::vector<ObjectRecord>> ListObjects() override;
  absl::StatusOr<CreatedJob> CreateJob(const NewJob& job) override;
  absl::StatusOr<JobRecord> GetJob(int64_t job_id) override;
  absl::StatusOr<std::vector<JobRecord>> ListJobs(int64_t object_id) override;
  absl::StatusOr<std::vector<JobRecord>> ListActiveJobs() override;
  void UpdateJobStateAsync(JobStateChange change, JobCallback done) override;
  absl::StatusOr<PlanRecord> GetPlan(int64_t job_id) override;
  void LeaseNextCommandAsync(const LeaseRequest& request, LeaseCallback done) override;
  absl::StatusOr<CommandRecord> GetCommand(int64_t command_id) override;
  absl::StatusOr<std::vector<CommandRecord>> ListCommands(int64_t job_id) override;
  absl::StatusOr<LeasedCounts> CountLeasedCommands(int64_t job_id, int64_t now_unix_ms) override;
  void AcceptTraceAsync(AcceptTraceRequest request, AcceptTraceCallback done) override;
  void FailCommandAsync(FailCommandRequest request, FailCommandCallback done) override;
  absl::StatusOr<TraceRecord> GetTrace(int64_t trace_id, bool include_samples) override;
  absl::StatusOr<std::vector<TraceRecord>> ListTraces(int64_t job_id, bool include_samples) override;
  absl::StatusOr<std::vector<TraceRecord>> ListTracesPage(int64_t job_id, int64_t after_trace_id, int limit,
                                                          bool include_samples) override;
  absl::StatusOr<JobActivity> GetJobActivity(int64_t job_id) override;
  absl::StatusOr<int64_t> FindImportedTrace(int64_t job_id, const std::string& sha256) override;
  absl::StatusOr<RigRegistrationRecord> AddRigRegistration(const NewRigRegistration& registration) override;
  absl::StatusOr<RigRegistrationRecord> GetRigRegistration(int64_t registration_id) override;
  absl::StatusOr<std::vector<RigRegistrationRecord>> ListRigRegistrations(int64_t object_id) override;
  absl::StatusOr<TraceFrameRecord> GetTraceFrame(int64_t trace_id) override;
  absl::StatusOr<FitRecord> GetFit(int64_t trace_id, int32_t version) override;
  absl::StatusOr<std::vector<FitRecord>> AddFits(const std::vector<TraceRefit>& fits) override;
  absl::StatusOr<std::vector<FitRecord>> ListFits(int64_t job_id, int32_t version) override;
  absl::StatusOr<SampleRecord> ReadSample(int64_t trace_id, int32_t fit_version, bool include_samples) override;
  absl::StatusOr<std::vector<SampleRecord>> ReadJobSamples(int64_t job_id, int32_t fit_version) override;
  void SyncAsync(std::function<void(absl::Status)> done) override;
  void RecordRejectedTraceAsync(NewRejectedTrace trace, RejectedCallback done) override;
  absl::StatusOr<std::vector<RejectedTraceRecord>> ListRejectedTraces(int64_t job_id) override;
  absl::StatusOr<RejectedTraceRecord> GetRejectedTrace(int64_t id) override;
  absl::StatusOr<std::vector<EventRecord>> ListEvents(int64_t job_id, int64_t after_id, int limit) override;
  absl::StatusOr<std::vector<EventRecord>> ListEventsNewestFirst(int64_t job_id, int64_t before_id,
                                                                 int limit) override;

 private:
  // One write on its way: `forward` hands it to the wrapped store (with a
  // wrapped callback), `fail` completes it with an injected error.
  struct PendingWrite {
    int64_t number = 0;
    absl::Time submitted;
    std::function<void()> forward;
    std::function<void(absl::Status)> fail;
  };

  // Numbers the write and queues it for the dispatcher; in kInline mode waits
  // until its callback was delivered, then runs it on this thread.
  template <typename T>
  void SubmitWrite(std::function<void(std::function<void(absl::StatusOr<T>)>)> forward,
                   std::function<void(absl::StatusOr<T>)> done);
  template <typename T>
  absl::StatusOr<T> RunWrite(std::function<void(std::function<void(absl::StatusOr<T>)>)> forward);
  void Dispatch();
  bool HasWorkOrStopping() const ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu_) { return stopping_ || !queue_.empty(); }

  Store* const wrapped_;
  mutable Mutex mu_;
  std::deque<PendingWrite> queue_ ABSL_GUARDED_BY(mu_);
  int64_t submitted_ ABSL_GUARDED_BY(mu_) = 0;
  std::map<int64_t, absl::Status> fail_ ABSL_GUARDED_BY(mu_);
  int64_t fail_from_ ABSL_GUARDED_BY(mu_) = 0;  // 0 = off
  absl::Status fail_from_status_ ABSL_GUARDED_BY(mu_);
  std::map<int64_t, absl::Duration> delay_ ABSL_GUARDED_BY(mu_);
  std::map<int64_t, bool> hold_ ABSL_GUARDED_BY(mu_);  // n -> released
  int64_t holding_ ABSL_GUARDED_BY(mu_) = 0;            // the write the dispatcher waits on
  CallbackDelivery delivery_ ABSL_GUARDED_BY(mu_) = CallbackDelivery::kAsWrapped;
  absl::Duration late_by_ ABSL_GUARDED_BY(mu_) = absl::ZeroDuration();
  bool stopping_ ABSL_GUARDED_BY(mu_) = false;
  TaskQueue late_callbacks_;
  std::thread dispatcher_;  // last
};

}  // namespace surfmap
