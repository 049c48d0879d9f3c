// The job layer against a store whose writes can be held, failed, delayed or
// answered inline: nothing may wait on storage under a lock, callbacks must
// only post, and after a failed write memory and database must agree.
#include "server/jobs/job_coordinator.h"

#include <atomic>
#include <thread>

#include <sqlite3.h>

#include "gtest/gtest.h"
#include "server/jobs/coordinator_fixture_for_test.h"
#include "server/jobs/job_refit.h"

namespace surfmap::testing {
namespace {

using CallbackDelivery = FaultInjectingStore::CallbackDelivery;

class JobCoordinatorTest : public CoordinatorFixture {};

TEST_F(JobCoordinatorTest, SteeringNeverWaitsForTheStoreAndAnswersWhenDurable) {
  const int64_t object = UploadPlate();
  const JobSnapshot job = CreateUniformJob(object);
  absl::StatusOr<LeaseOutcome> lease = Lease(job.record.id, "rig-a");
  ASSERT_TRUE(lease.ok() && lease->record) << lease.status();

  // Hold the next write (the pause): the call must return at once.
  const int64_t pause_write = faults_->writes_submitted() + 1;
  faults_->HoldWrite(pause_write);
  Awaited<absl::StatusOr<JobSnapshot>> paused;
  const auto start = std::chrono::steady_clock::now();
  coordinator_->SetJobState(job.record.id, JobState::kPaused, paused.Callback());
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(1)) << "SetJobState waited for the store";
  ASSERT_TRUE(faults_->WaitUntilHeld(pause_write, absl::Seconds(10)));
  EXPECT_FALSE(paused.Ready()) << "answered before the change was durable";

  // While the pause is held: reads answer, and a rig's trace is taken (its
  // write queues behind the pause, as on a slow disk).
  absl::StatusOr<JobSnapshot> during = coordinator_->GetJob(job.record.id);
  ASSERT_TRUE(during.ok()) << during.status();
  EXPECT_EQ(during->record.state, JobState::kRunning) << "the job shows the stored state until the pause is durable";
  Awaited<absl::StatusOr<SubmitOutcome>> submitted;
  const DragTrace trace = TraceFor(*lease);
  coordinator_->probes().SubmitTrace(
      lease->record->id, "rig-a", [trace]() -> absl::StatusOr<DragTrace> { return trace; }, false,
      submitted.Callback());
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  EXPECT_FALSE(submitted.Ready()) << "the trace was acknowledged before its (queued) write";

  faults_->ReleaseWrite(pause_write);
  std::optional<absl::StatusOr<JobSnapshot>> pause_answer = paused.Get("pause");
  ASSERT_TRUE(pause_answer && pause_answer->ok()) << (pause_answer ? pause_answer->status() : absl::Status());
  EXPECT_EQ((*pause_answer)->record.state, JobState::kPaused);
  std::optional<absl::StatusOr<SubmitOutcome>> submit_answer = submitted.Get("submit");
  ASSERT_TRUE(submit_answer && submit_answer->ok()) << (submit_answer ? submit_answer->status() : absl::Status());
  EXPECT_FALSE((*submit_answer)->already_accepted);
}

TEST_F(JobCoordinatorTest, SteeringIsAnsweredWhileTheLongWorkPoolIsBusy) {
  const int64_t object = UploadPlate();
  const JobSnapshot job = CreateUniformJob(object);
  // Every long-work thread busy (as with map builds for several watchers)
  // until the pause has been answered or has timed out.
  std::promise<void> release;
  std::shared_future<void> released = release.get_future().share();
  std::atomic<int> busy{0};
  for (int i = 0; i < pool_->threads(); ++i) {
    pool_->Post([&busy, released] {
      ++busy;
      released.wait();
    });
  }
  while (busy.load() < pool_->threads()) std::this_thread::yield();

  Awaited<absl::StatusOr<JobSnapshot>> paused;
  coordinator_->SetJobState(job.record.id, JobState::kPaused, paused.Callback());
  std::optional<absl::StatusOr<JobSnapshot>> answer = paused.Get("pause while the long-work pool is busy");
  release.set_value();
  ASSERT_TRUE(answer && answer->ok()) << (answer ? answer->status() : absl::Status());
  EXPECT_EQ((*answer)->record.state, JobState::kPaused);
}

TEST_F(JobCoordinatorTest, InlineCallbacksCannotDeadlock) {
  // The store answers on the calling thread, which may hold a job lock: the
  // coordinator must only post from its callbacks.
  faults_->SetCallbackDelivery(CallbackDelivery::kInline);
  const int64_t object = UploadPlate();
  const JobSnapshot job = CreateUniformJob(object, /*budget=*/8);
  ASSERT_TRUE(SetState(job.record.id, JobState::kPaused).ok());
  ASSERT_TRUE(SetState(job.record.id, JobState::kRunning).ok());
  EXPECT_EQ(MeasureUntilDone(job.record.id, "rig-inline"), 8);
  absl::StatusOr<JobSnapshot> done = coordinator_->GetJob(job.record.id);
  ASSERT_TRUE(done.ok());
  EXPECT_EQ(done->record.state, JobState::kCompleted);
}

TEST_F(JobCoordinatorTest, LateCallbacksKeepCommitOrder) {
  faults_->SetCallbackDelivery(CallbackDelivery::kLate, absl::Milliseconds(15));
  const int64_t object = UploadPlate();
  const JobSnapshot job = CreateUniformJob(object, /*budget=*/6);
  EXPECT_EQ(MeasureUntilDone(job.record.id, "rig-late"), 6);
  absl::StatusOr<JobSnapshot> done = coordinator_->GetJob(job.record.id);
  ASSERT_TRUE(done.ok());
  EXPECT_EQ(done->record.state, JobState::kCompleted);
  EXPECT_EQ(done->progress.measured, 6);
}

TEST_F(JobCoordinatorTest, AFailedTraceWriteIsUndoneByReReadingTheJob) {
  const int64_t object = UploadPlate();
  const JobSnapshot job = CreateUniformJob(object);
  absl::StatusOr<LeaseOutcome> lease = Lease(job.record.id, "rig-a");
  ASSERT_TRUE(lease.ok() && lease->record);
  faults_->FailWrite(faults_->writes_submitted() + 1, absl::UnavailableError("disk full"));
  absl::StatusOr<SubmitOutcome> failed = Submit(lease->record->id, "rig-a", TraceFor(*lease));
  EXPECT_EQ(failed.status().code(), absl::StatusCode::kUnavailable) << failed.status();

  // The plan had counted the site measured; the database has no trace. After
  // the re-read the job agrees with the database, and the rig's retry lands.
  absl::StatusOr<SubmitOutcome> retried = absl::UnavailableError("not tried");
  for (int i = 0; i < 200 && retried.status().code() == absl::StatusCode::kUnavailable; ++i) {
    retried = Submit(lease->record->id, "rig-a", TraceFor(*lease));
    if (!retried.ok()) std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  ASSERT_TRUE(retried.ok()) << retried.status();
  EXPECT_FALSE(retried->already_accepted);
  absl::StatusOr<JobSnapshot> now = coordinator_->GetJob(job.record.id);
  ASSERT_TRUE(now.ok());
  EXPECT_EQ(now->progress.measured, 1);

  // A fresh coordinator on the same database sees the same plan.
  const PlanProgress before = now->progress;
  Reopen();
  absl::StatusOr<JobSnapshot> reloaded = coordinator_->GetJob(job.record.id);
  ASSERT_TRUE(reloaded.ok()) << reloaded.status();
  EXPECT_EQ(reloaded->progress.measured, before.measured);
  EXPECT_EQ(reloaded->progress.issued, before.issued);
  EXPECT_EQ(reloaded->progress.pending, before.pending);
}

TEST_F(JobCoordinatorTest, AWriteQueuedBehindAFailedOneIsAnsweredRetryAndItsRetryLands) {
  // Found by the chaos soak: rig A's write fails in the store (its lease was
  // taken over), and rig B's write, queued behind it on a plan revision that
  // counted A's answer, is refused by the store's revision guard. B did
  // nothing wrong: it must hear UNAVAILABLE (retry), not ABORTED, and its
  // retry must land once the job was re-read.
  const int64_t object = UploadPlate();
  const JobSnapshot job = CreateUniformJob(object);
  absl::StatusOr<LeaseOutcome> lease_a = Lease(job.record.id, "rig-a");
  absl::StatusOr<LeaseOutcome> lease_b = Lease(job.record.id, "rig-b");
  ASSERT_TRUE(lease_a.ok() && lease_a->record) << lease_a.status();
  ASSERT_TRUE(lease_b.ok() && lease_b->record) << lease_b.status();

  const int64_t write_a = faults_->writes_submitted() + 1;
  faults_->HoldWrite(write_a);
  faults_->FailWrite(write_a, absl::FailedPreconditionError("command is leased to 'rig-c', not to 'rig-a'"));
  Awaited<absl::StatusOr<SubmitOutcome>> submitted_a;
  const DragTrace trace_a = TraceFor(*lease_a);
  coordinator_->probes().SubmitTrace(
      lease_a->record->id, "rig-a", [trace_a]() -> absl::StatusOr<DragTrace> { return trace_a; }, false,
      submitted_a.Callback());
  ASSERT_TRUE(faults_->WaitUntilHeld(write_a, absl::Seconds(10)));
  Awaited<absl::StatusOr<SubmitOutcome>> submitted_b;
  const DragTrace trace_b = TraceFor(*lease_b);
  coordinator_->probes().SubmitTrace(
      lease_b->record->id, "rig-b", [trace_b]() -> absl::StatusOr<DragTrace> { return trace_b; }, false,
      submitted_b.Callback());
  // B's write is queued behind A's (the store numbers it write_a + 1).
  for (int i = 0; i < 500 && faults_->writes_submitted() < write_a + 1; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  ASSERT_GE(faults_->writes_submitted(), write_a + 1) << "rig-b's write never reached the store";
  faults_->ReleaseWrite(write_a);

  std::optional<absl::StatusOr<SubmitOutcome>> answer_a = submitted_a.Get("rig-a's submit");
  ASSERT_TRUE(answer_a.has_value());
  EXPECT_EQ(answer_a->status().code(), absl::StatusCode::kFailedPrecondition) << answer_a->status();
  std::optional<absl::StatusOr<SubmitOutcome>> answer_b = submitted_b.Get("rig-b's submit");
  ASSERT_TRUE(answer_b.has_value());
  EXPECT_EQ(answer_b->status().code(), absl::StatusCode::kUnavailable) << answer_b->status();

  absl::StatusOr<SubmitOutcome> retried = absl::UnavailableError("not tried");
  for (int i = 0; i < 200 && retried.status().code() == absl::StatusCode::kUnavailable; ++i) {
    retried = Submit(lease_b->record->id, "rig-b", trace_b);
    if (!retried.ok()) std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  ASSERT_TRUE(retried.ok()) << retried.status();
  EXPECT_FALSE(retried->already_accepted);
  absl::StatusOr<JobSnapshot> now = coordinator_->GetJob(job.record.id);
  ASSERT_TRUE(now.ok()) << now.status();
  EXPECT_EQ(now->progress.measured, 1) << "only rig-b's trace is stored";
}

TEST_F(JobCoordinatorTest, AFailedStateWriteLeavesTheStoredState) {
  const int64_t object = UploadPlate();
  const JobSnapshot job = CreateUniformJob(object);
  faults_->FailWrite(faults_->writes_submitted() + 1, absl::UnavailableError("I/O error"));
  EXPECT_EQ(SetState(job.record.id, JobState::kCancelled).status().code(), absl::StatusCode::kUnavailable);
  // Memory had moved to cancelled (and skipped the pending sites); the re-read
  // puts it back, and the next change goes through.
  absl::StatusOr<JobSnapshot> paused = absl::UnavailableError("not tried");
  for (int i = 0; i < 200 && paused.status().code() == absl::StatusCode::kUnavailable; ++i) {
    paused = SetState(job.record.id, JobState::kPaused);
    if (!paused.ok()) std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  ASSERT_TRUE(paused.ok()) << paused.status();
  EXPECT_EQ(paused->record.state, JobState::kPaused);
  EXPECT_EQ(paused->progress.skipped, 0) << "the failed cancel's skipped sites came back";
}

TEST_F(JobCoordinatorTest, AnOperatorsCancelWaitsOutTheReReadInsteadOfBeingToldToRetry) {
  // Found by the chaos soak: a rig's trace was refused by the store (its lease
  // had been taken over), the job was being re-read, and the operator's
  // CancelJob in that window was answered UNAVAILABLE. Rigs retry; an
  // operator's cancel should simply happen once the job is re-read.
  const int64_t object = UploadPlate();
  const JobSnapshot job = CreateUniformJob(object);
  const int64_t reread_barrier = HoldJobInReRead(job.record.id);
  ASSERT_NE(reread_barrier, 0);

  Awaited<absl::StatusOr<JobSnapshot>> cancelled;
  coordinator_->SetJobState(job.record.id, JobState::kCancelled, cancelled.Callback());
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  EXPECT_FALSE(cancelled.Ready()) << "answered while the job was still waiting to be re-read";

  faults_->ReleaseWrite(reread_barrier);
  std::optional<absl::StatusOr<JobSnapshot>> answer = cancelled.Get("cancel behind the re-read");
  ASSERT_TRUE(answer.has_value());
  ASSERT_TRUE(answer->ok()) << answer->status();
  EXPECT_EQ((*answer)->record.state, JobState::kCancelled);
  EXPECT_EQ((*answer)->progress.measured, 0) << "the refused trace came back into the plan";
  absl::StatusOr<JobRecord> stored = sqlite_->GetJob(job.record.id);
  ASSERT_TRUE(stored.ok()) << stored.status();
  EXPECT_EQ(stored->state, JobState::kCancelled) << "the cancel answered OK but is not in the database";
}

TEST_F(JobCoordinatorTest, ListenersRunWithNoLockHeldAndMayCallBack) {
  const int64_t object = UploadPlate();
  const JobSnapshot job = CreateUniformJob(object, /*budget=*/4);
  std::atomic<int> calls{0};
  std::atomic<bool> failed{false};
  absl::StatusOr<JobCoordinator::WatchHandle> handle = coordinator_->Watch(job.record.id, [&] {
    // Under a job lock this would deadlock (Mutex is not re-entrant).
    if (!coordinator_->GetJob(job.record.id).ok()) failed = true;
    calls.fetch_add(1);
  });
  ASSERT_TRUE(handle.ok());
  ASSERT_TRUE(SetState(job.record.id, JobState::kPaused).ok());
  ASSERT_TRUE(SetState(job.record.id, JobState::kRunning).ok());
  EXPECT_EQ(MeasureUntilDone(job.record.id, "rig"), 4);
  completions_->Drain();
  EXPECT_GE(calls.load(), 6) << "two state changes and four traces";
  EXPECT_FALSE(failed.load());
  JobCoordinator::Unwatch(*handle);
}

TEST_F(JobCoordinatorTest, AnObjectAskedForBeforeItExistsIsFoundOnceUploaded) {
  EXPECT_EQ(coordinator_->Surface(1, 0).status().code(), absl::StatusCode::kNotFound);
  const int64_t object = UploadPlate();
  ASSERT_EQ(object, 1);
  absl::StatusOr<std::shared_ptr<const LoopSurface>> surface = coordinator_->Surface(1, 0);
  EXPECT_TRUE(surface.ok()) << surface.status();
}

TEST_F(JobCoordinatorTest, OnlyRunningAndPausedJobsAreLoadedAtStart) {
  const int64_t object = UploadPlate();
  const JobSnapshot running = CreateUniformJob(object);
  const JobSnapshot paused = CreateUniformJob(object);
  const JobSnapshot cancelled = CreateUniformJob(object);
  const JobSnapshot completed = CreateUniformJob(object, /*budget=*/2);
  ASSERT_TRUE(SetState(paused.record.id, JobState::kPaused).ok());
  ASSERT_TRUE(SetState(cancelled.record.id, JobState::kCancelled).ok());
  ASSERT_EQ(MeasureUntilDone(completed.record.id, "rig"), 2);
  Reopen();
  EXPECT_EQ(coordinator_->registry().loaded_jobs(), 2u);
  EXPECT_TRUE(coordinator_->IsJobLoaded(running.record.id));
  EXPECT_TRUE(coordinator_->IsJobLoaded(paused.record.id));
  EXPECT_FALSE(coordinator_->IsJobLoaded(completed.record.id));
  // A finished job is still there on demand.
  absl::StatusOr<JobSnapshot> done = coordinator_->GetJob(completed.record.id);
  ASSERT_TRUE(done.ok()) << done.status();
  EXPECT_EQ(done->record.state, JobState::kCompleted);
  EXPECT_EQ(done->progress.measured, 2);
}

// A registered rig's lease answer traces the command's path on the surface
// (for its rig-frame command): that runs on a pool, not on the completions
// thread every store completion waits behind in commit order.
TEST_F(JobCoordinatorTest, ARigFrameLeaseIsComputedOffTheCompletionsThread) {
  const int64_t object = UploadPlate();
  const JobSnapshot job = CreateUniformJob(object);
  RigRegistration registration;
  registration.object_translation_mm = {400.0, 0.0, 0.0};
  registration.tip_radius_mm = 2.0;
  absl::StatusOr<RegisteredRig> rig = coordinator_->rigs().Register(object, "arm", registration);
  ASSERT_TRUE(rig.ok()) << rig.status();
  std::thread::id completions_thread;
  completions_->Post([&] { completions_thread = std::this_thread::get_id(); });
  completions_->Drain();

  using Answered = std::pair<std::thread::id, absl::StatusOr<LeaseOutcome>>;
  Awaited<Answered> leased;
  coordinator_->probes().LeaseCommand("arm", job.record.id,
                                      [done = leased.Callback()](absl::StatusOr<LeaseOutcome> o) {
                                        done(Answered{std::this_thread::get_id(), std::move(o)});
                                      });
  std::optional<Answered> lease = leased.Get("LeaseCommand");
  ASSERT_TRUE(lease && lease->second.ok() && lease->second->record);
  EXPECT_NE(lease->first, completions_thread);
  ASSERT_TRUE(lease->second->rig_frame);
  ASSERT_TRUE(lease->second->rig_registration);
  EXPECT_EQ(lease->second->rig_registration->record.id, rig->record.id);
  EXPECT_GE(lease->second->rig_frame->tool_centre_path.size(), 2u);

  // The next lease that comes with an accepted trace, likewise.
  using Submitted = std::pair<std::thread::id, absl::StatusOr<SubmitOutcome>>;
  Awaited<Submitted> submitted;
  const DragTrace trace = TraceFor(*lease->second);
  coordinator_->probes().SubmitTrace(
      lease->second->record->id, "arm", [trace]() -> absl::StatusOr<DragTrace> { return trace; },
      /*lease_next=*/true, [done = submitted.Callback()](absl::StatusOr<SubmitOutcome> o) {
        done(Submitted{std::this_thread::get_id(), std::move(o)});
      });
  std::optional<Submitted> answer = submitted.Get("SubmitTrace");
  ASSERT_TRUE(answer && answer->second.ok()) << (answer ? answer->second.status() : absl::OkStatus());
  EXPECT_NE(answer->first, completions_thread);
  ASSERT_TRUE(answer->second->next && answer->second->next->record && answer->second->next->rig_frame);
  EXPECT_GE(answer->second->next->rig_frame->tool_centre_path.size(), 2u);
  ASSERT_TRUE(answer->second->next->rig_registration);
  EXPECT_EQ(answer->second->next->rig_registration->record.id, rig->record.id);
}

TEST_F(JobCoordinatorTest, ACancelledJobStillAcknowledgesTheIdenticalRetry) {
  const int64_t object = UploadPlate();
  const JobSnapshot job = CreateUniformJob(object);
  absl::StatusOr<LeaseOutcome> lease = Lease(job.record.id, "rig-a");
  ASSERT_TRUE(lease.ok() && lease->record);
  const DragTrace trace = TraceFor(*lease);
  absl::StatusOr<SubmitOutcome> first = Submit(lease->record->id, "rig-a", trace);
  ASSERT_TRUE(first.ok()) << first.status();
  ASSERT_TRUE(SetState(job.record.id, JobState::kCancelled).ok());
  absl::StatusOr<SubmitOutcome> retry = Submit(lease->record->id, "rig-a", trace);
  ASSERT_TRUE(retry.ok()) << retry.status();
  EXPECT_TRUE(retry->already_accepted);
  EXPECT_EQ(retry->trace_id, first->trace_id);
  EXPECT_EQ(retry->fit.mu, first->fit.mu);
  // Other samples are not silently dropped behind an OK.
  absl::StatusOr<SubmitOutcome> other = Submit(lease->record->id, "rig-a", TraceFor(*lease, /*seed=*/99));
  EXPECT_EQ(other.status().code(), absl::StatusCode::kAlreadyExists) << other.status();
}

TEST_F(JobCoordinatorTest, RefitsReadTracesPageByPage) {
  const int64_t object = UploadPlate();
  const JobSnapshot job = CreateUniformJob(object, /*budget=*/5);
  ASSERT_EQ(MeasureUntilDone(job.record.id, "rig"), 5);
  FitOptions options;
  options.ar_order = 3;
  absl::StatusOr<RefitOutcome> refit = RefitJobTraces(*faults_, coordinator_->rigs(), job.record.id, options,
                                                      /*page_traces=*/2);
  ASSERT_TRUE(refit.ok()) << refit.status();
  EXPECT_EQ(refit->refitted, 5) << "three pages of 2, 2 and 1 traces";
  EXPECT_EQ(refit->version, 2);
  absl::StatusOr<std::vector<SampleRecord>> samples = coordinator_->reads().ListSamples(job.record.id, 2);
  ASSERT_TRUE(samples.ok());
  EXPECT_EQ(samples->size(), 5u);
}

// A refit converts a rig-frame trace with its registration from memory,
// decoded once: the stored row is not read again. Shown by damaging the
// stored JSON after registering (a re-read would answer DATA_LOSS).
TEST_F(JobCoordinatorTest, ARefitConvertsRigFrameTracesWithTheRegistrationInMemory) {
  const int64_t object = UploadPlate();
  const JobSnapshot job = CreateUniformJob(object, /*budget=*/1);
  RigRegistration registration;
  registration.object_translation_mm = {400.0, -50.0, 20.0};
  registration.tip_radius_mm = 1.0;
  absl::StatusOr<RegisteredRig> rig = coordinator_->rigs().Register(object, "arm", registration);
  ASSERT_TRUE(rig.ok()) << rig.status();
  absl::StatusOr<LeaseOutcome> lease = Lease(job.record.id, "arm");
  ASSERT_TRUE(lease.ok() && lease->record);
  const DragTrace in_base = TraceFromObjectFrame(TraceFor(*lease), TraceFrame::kRigBase, registration);
  Awaited<absl::StatusOr<SubmitOutcome>> submitted;
  coordinator_->probes().SubmitTrace(
      lease->record->id, "arm", [in_base]() -> absl::StatusOr<DragTrace> { return in_base; }, /*lease_next=*/false,
      ProbeProtocol::TraceFrameChoice{TraceFrame::kRigBase, 0}, submitted.Callback());
  std::optional<absl::StatusOr<SubmitOutcome>> accepted = submitted.Get("SubmitTrace");
  ASSERT_TRUE(accepted && accepted->ok()) << (accepted ? accepted->status() : absl::OkStatus());

  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open(dir_.Path("surfmap.db").c_str(), &db), SQLITE_OK);
  const char* damage = "UPDATE rig_registrations SET registration_json = '{\"damaged\": 1}'";
  ASSERT_EQ(sqlite3_exec(db, damage, nullptr, nullptr, nullptr), SQLITE_OK);
  sqlite3_close(db);
  ASSERT_FALSE(DecodeRegistration(*faults_->GetRigRegistration(rig->record.id)).ok());

  absl::StatusOr<RefitOutcome> refit = coordinator_->RefitJob(job.record.id, FitOptions{});
  ASSERT_TRUE(refit.ok()) << refit.status();
  EXPECT_EQ(refit->refitted, 1);
  EXPECT_EQ(refit->failed, 0);
}

}  // namespace
}  // namespace surfmap::testing
