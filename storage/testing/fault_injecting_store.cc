#include "storage/testing/fault_injecting_store.h"

#include <optional>

#include "server/base/mutex.h"

namespace surfmap {

FaultInjectingStore::FaultInjectingStore(Store* wrapped) : wrapped_(wrapped), dispatcher_([this] { Dispatch(); }) {}

FaultInjectingStore::~FaultInjectingStore() {
  {
    MutexLock lock(&mu_);
    stopping_ = true;  // releases holds; the dispatcher forwards what is queued
  }
  dispatcher_.join();
  // Every forwarded write's callback has been called (or posted) once the
  // wrapped store passes this barrier.
  Notification synced;
  wrapped_->SyncAsync([&synced](absl::Status) { synced.Notify(); });
  synced.WaitForNotification();
  late_callbacks_.Drain();
}

void FaultInjectingStore::FailWrite(int64_t n, absl::Status status) {
  MutexLock lock(&mu_);
  fail_[n] = std::move(status);
}

void FaultInjectingStore::FailWritesFrom(int64_t n, absl::Status status) {
  MutexLock lock(&mu_);
  fail_from_ = n;
  fail_from_status_ = std::move(status);
}

void FaultInjectingStore::HealWrites() {
  MutexLock lock(&mu_);
  fail_from_ = 0;
}

void FaultInjectingStore::DelayWrite(int64_t n, absl::Duration delay) {
  MutexLock lock(&mu_);
  delay_[n] = delay;
}

void FaultInjectingStore::HoldWrite(int64_t n) {
  MutexLock lock(&mu_);
  hold_[n] = false;
}

void FaultInjectingStore::ReleaseWrite(int64_t n) {
  MutexLock lock(&mu_);
  hold_[n] = true;
}

bool FaultInjectingStore::WaitUntilHeld(int64_t n, absl::Duration timeout) {
  MutexLock lock(&mu_);
  auto held = [this, n]() ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu_) { return holding_ == n; };
  return mu_.AwaitWithTimeout(held, absl::ToChronoMilliseconds(timeout));
}

void FaultInjectingStore::SetCallbackDelivery(CallbackDelivery delivery, absl::Duration late_by) {
  MutexLock lock(&mu_);
  delivery_ = delivery;
  late_by_ = late_by;
}

int64_t FaultInjectingStore::writes_submitted() const {
  MutexLock lock(&mu_);
  return submitted_;
}

template <typename T>
void FaultInjectingStore::SubmitWrite(std::function<void(std::function<void(absl::StatusOr<T>)>)> forward,
                                      std::function<void(absl::StatusOr<T>)> done) {
  CallbackDelivery delivery;
  absl::Duration late_by;
  {
    MutexLock lock(&mu_);
    delivery = delivery_;
    late_by = late_by_;
  }
  struct InlineSlot {
    Notification delivered;
    std::optional<absl::StatusOr<T>> result;
  };
  std::shared_ptr<InlineSlot> slot;
  std::function<void(absl::StatusOr<T>)> deliver;
  switch (delivery) {
    case CallbackDelivery::kAsWrapped:
      deliver = std::move(done);
      break;
    case CallbackDelivery::kLate:
      deliver = [this, done = std::move(done), late_by](absl::StatusOr<T> result) {
        auto shared = std::make_shared<absl::StatusOr<T>>(std::move(result));
        late_callbacks_.Post([done, shared, late_by] {
          absl::SleepFor(late_by);
          done(std::move(*shared));
        });
      };
      break;
    case CallbackDelivery::kInline:
      slot = std::make_shared<InlineSlot>();
      deliver = [slot](absl::StatusOr<T> result) {
        slot->result = std::move(result);
        slot->delivered.Notify();
      };
      break;
  }
  PendingWrite write;
  write.forward = [forward = std::move(forward), deliver] { forward(deliver); };
  write.fail = [deliver](absl::Status status) { deliver(std::move(status)); };
  bool refused = false;
  {
    MutexLock lock(&mu_);
    if (stopping_) {
      refused = true;
    } else {
      write.number = ++submitted_;
      write.submitted = absl::Now();
      queue_.push_back(write);
    }
  }
  if (refused) write.fail(absl::UnavailableError("fault-injecting store is shutting down"));
  if (slot) {
    slot->delivered.WaitForNotification();
    done(std::move(*slot->result));
  }
}

template <typename T>
absl::StatusOr<T> FaultInjectingStore::RunWrite(std::function<void(std::function<void(absl::StatusOr<T>)>)> forward) {
  auto slot = std::make_shared<std::pair<Notification, std::optional<absl::StatusOr<T>>>>();
  PendingWrite write;
  auto deliver = [slot](absl::StatusOr<T> result) {
    slot->second = std::move(result);
    slot->first.Notify();
  };
  write.forward = [forward = std::move(forward), deliver] { forward(deliver); };
  write.fail = [deliver](absl::Status status) { deliver(std::move(status)); };
  {
    MutexLock lock(&mu_);
    if (stopping_) return absl::UnavailableError("fault-injecting store is shutting down");
    write.number = ++submitted_;
    write.submitted = absl::Now();
    queue_.push_back(write);
  }
  slot->first.WaitForNotification();
  return std::move(*slot->second);
}

void FaultInjectingStore::Dispatch() {
  for (;;) {
    PendingWrite write;
    std::optional<absl::Status> injected;
    absl::Duration delay = absl::ZeroDuration();
    {
      MutexLock lock(&mu_);
      mu_.Await([this]() ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu_) { return HasWorkOrStopping(); });
      if (queue_.empty()) return;  // stopping and drained
      write = std::move(queue_.front());
      queue_.pop_front();
      const int64_t n = write.number;
      if (hold_.count(n)) {
        holding_ = n;
        auto released = [this, n]() ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu_) { return hold_[n] || stopping_; };
        mu_.Await(released);
        holding_ = 0;
      }
      if (auto it = delay_.find(n); it != delay_.end()) delay = it->second;
      if (auto it = fail_.find(n); it != fail_.end()) {
        injected = it->second;
      } else if (fail_from_ > 0 && n >= fail_from_) {
        injected = fail_from_status_;
      }
    }
    const absl::Duration wait = write.submitted + delay - absl::Now();
    if (wait > absl::ZeroDuration()) absl::SleepFor(wait);
    if (injected.has_value()) {
      write.fail(*injected);
    } else {
      write.forward();
    }
  }
}

// ---- Writes: numbered, ordered, subject to the injected faults ----

absl::StatusOr<int64_t> FaultInjectingStore::CreateObject(const NewObject& object) {
  return RunWrite<int64_t>([this, &object](std::function<void(absl::StatusOr<int64_t>)> done) {
    done(wrapped_->CreateObject(object));
  });
}

absl::StatusOr<CreatedJob> FaultInjectingStore::CreateJob(const NewJob& job) {
  return RunWrite<CreatedJob>(
      [this, &job](std::function<void(absl::StatusOr<CreatedJob>)> done) { done(wrapped_->CreateJob(job)); });
}

absl::StatusOr<std::vector<FitRecord>> FaultInjectingStore::AddFits(const std::vector<TraceRefit>& fits) {
  return RunWrite<std::vector<FitRecord>>(
      [this, &fits](std::function<void(absl::StatusOr<std::vector<FitRecord>>)> done) {
        done(wrapped_->AddFits(fits));
      });
}

void FaultInjectingStore::UpdateJobStateAsync(JobStateChange change, JobCallback done) {
  auto shared = std::make_shared<JobStateChange>(std::move(change));
  SubmitWrite<JobRecord>(
      [this, shared](JobCallback forward_done) { wrapped_->UpdateJobStateAsync(*shared, std::move(forward_done)); },
      std::move(done));
}

void FaultInjectingStore::LeaseNextCommandAsync(const LeaseRequest& request, LeaseCallback done) {
  SubmitWrite<std::optional<CommandRecord>>(
      [this, request](LeaseCallback forward_done) { wrapped_->LeaseNextCommandAsync(request, std::move(forward_done)); },
      std::move(done));
}

void FaultInjectingStore::AcceptTraceAsync(AcceptTraceRequest request, AcceptTraceCallback done) {
  auto shared = std::make_shared<AcceptTraceRequest>(std::move(request));
  SubmitWrite<AcceptTraceResult>(
      [this, shared](AcceptTraceCallback forward_done) {
        wrapped_->AcceptTraceAsync(std::move(*shared), std::move(forward_done));
      },
      std::move(done));
}

void FaultInjectingStore::FailCommandAsync(FailCommandRequest request, FailCommandCallback done) {
  auto shared = std::make_shared<FailCommandRequest>(std::move(request));
  SubmitWrite<FailCommandResult>(
      [this, shared](FailCommandCallback forward_done) {
        wrapped_->FailCommandAsync(std::move(*shared), std::move(forward_done));
      },
      std::move(done));
}

void FaultInjectingStore::SyncAsync(std::function<void(absl::Status)> done) {
  SubmitWrite<bool>(
      [this](std::function<void(absl::StatusOr<bool>)> forward_done) {
        wrapped_->SyncAsync([forward_done](absl::Status s) {
          forward_done(s.ok() ? absl::StatusOr<bool>(true) : absl::StatusOr<bool>(s));
        });
      },
      [done = std::move(done)](absl::StatusOr<bool> r) { done(r.status()); });
}

void FaultInjectingStore::RecordRejectedTraceAsync(NewRejectedTrace trace, RejectedCallback done) {
  auto shared = std::make_shared<NewRejectedTrace>(std::move(trace));
  SubmitWrite<int64_t>(
      [this, shared](RejectedCallback forward_done) {
        wrapped_->RecordRejectedTraceAsync(std::move(*shared), std::move(forward_done));
      },
      std::move(done));
}

// ---- Reads: straight through ----

absl::StatusOr<std::vector<RejectedTraceRecord>> FaultInjectingStore::ListRejectedTraces(int64_t job_id) {
  return wrapped_->ListRejectedTraces(job_id);
}
absl::StatusOr<RejectedTraceRecord> FaultInjectingStore::GetRejectedTrace(int64_t id) {
  return wrapped_->GetRejectedTrace(id);
}

absl::StatusOr<ObjectRecord> FaultInjectingStore::GetObject(int64_t id, bool include_mesh) {
  return wrapped_->GetObject(id, include_mesh);
}
absl::StatusOr<std::vector<ObjectRecord>> FaultInjectingStore::ListObjects() { return wrapped_->ListObjects(); }
absl::StatusOr<JobRecord> FaultInjectingStore::GetJob(int64_t id) { return wrapped_->GetJob(id); }
absl::StatusOr<std::vector<JobRecord>> FaultInjectingStore::ListJobs(int64_t object_id) {
  return wrapped_->ListJobs(object_id);
}
absl::StatusOr<std::vector<JobRecord>> FaultInjectingStore::ListActiveJobs() { return wrapped_->ListActiveJobs(); }
absl::StatusOr<PlanRecord> FaultInjectingStore::GetPlan(int64_t job_id) { return wrapped_->GetPlan(job_id); }
absl::StatusOr<CommandRecord> FaultInjectingStore::GetCommand(int64_t id) { return wrapped_->GetCommand(id); }
absl::StatusOr<std::vector<CommandRecord>> FaultInjectingStore::ListCommands(int64_t job_id) {
  return wrapped_->ListCommands(job_id);
}
absl::StatusOr<LeasedCounts> FaultInjectingStore::CountLeasedCommands(int64_t job_id, int64_t now) {
  return wrapped_->CountLeasedCommands(job_id, now);
}
absl::StatusOr<TraceRecord> FaultInjectingStore::GetTrace(int64_t id, bool include_samples) {
  return wrapped_->GetTrace(id, include_samples);
}
absl::StatusOr<std::vector<TraceRecord>> FaultInjectingStore::ListTraces(int64_t job_id, bool include_samples) {
  return wrapped_->ListTraces(job_id, include_samples);
}
absl::StatusOr<std::vector<TraceRecord>> FaultInjectingStore::ListTracesPage(int64_t job_id, int64_t after, int limit,
                                                                             bool include_samples) {
  return wrapped_->ListTracesPage(job_id, after, limit, include_samples);
}
absl::StatusOr<int64_t> FaultInjectingStore::FindImportedTrace(int64_t job_id, const std::string& sha256) {
  return wrapped_->FindImportedTrace(job_id, sha256);
}

absl::StatusOr<JobActivity> FaultInjectingStore::GetJobActivity(int64_t job_id) {
  return wrapped_->GetJobActivity(job_id);
}
absl::StatusOr<RigRegistrationRecord> FaultInjectingStore::AddRigRegistration(
    const NewRigRegistration& registration) {
  return RunWrite<RigRegistrationRecord>(
      [this, &registration](std::function<void(absl::StatusOr<RigRegistrationRecord>)> done) {
        done(wrapped_->AddRigRegistration(registration));
      });
}
absl::StatusOr<RigRegistrationRecord> FaultInjectingStore::GetRigRegistration(int64_t registration_id) {
  return wrapped_->GetRigRegistration(registration_id);
}
absl::StatusOr<std::vector<RigRegistrationRecord>> FaultInjectingStore::ListRigRegistrations(int64_t object_id) {
  return wrapped_->ListRigRegistrations(object_id);
}
absl::StatusOr<TraceFrameRecord> FaultInjectingStore::GetTraceFrame(int64_t trace_id) {
  return wrapped_->GetTraceFrame(trace_id);
}
absl::StatusOr<FitRecord> FaultInjectingStore::GetFit(int64_t trace_id, int32_t version) {
  return wrapped_->GetFit(trace_id, version);
}
absl::StatusOr<std::vector<FitRecord>> FaultInjectingStore::ListFits(int64_t job_id, int32_t version) {
  return wrapped_->ListFits(job_id, version);
}
absl::StatusOr<SampleRecord> FaultInjectingStore::ReadSample(int64_t trace_id, int32_t version, bool include_samples) {
  return wrapped_->ReadSample(trace_id, version, include_samples);
}
absl::StatusOr<std::vector<SampleRecord>> FaultInjectingStore::ReadJobSamples(int64_t job_id, int32_t version) {
  return wrapped_->ReadJobSamples(job_id, version);
}
absl::StatusOr<std::vector<EventRecord>> FaultInjectingStore::ListEvents(int64_t job_id, int64_t after_id, int limit) {
  return wrapped_->ListEvents(job_id, after_id, limit);
}

absl::StatusOr<std::vector<EventRecord>> FaultInjectingStore::ListEventsNewestFirst(int64_t job_id, int64_t before_id,
                                                                                  int limit) {
  return wrapped_->ListEventsNewestFirst(job_id, before_id, limit);
}

}  // namespace surfmap
