// Test support for the job layer: a JobCoordinator over a real SQLite store
// wrapped in a FaultInjectingStore, with its own completion queue and pool,
// an object (a flat plate), simulated drags for its commands, and blocking
// forms of the asynchronous calls that FAIL the test instead of hanging when
// a callback never comes (a deadlock shows as a timeout, not a stuck test).
#pragma once

#include <chrono>
#include <future>
#include <memory>
#include <optional>
#include <string>

#include "absl/strings/str_cat.h"
#include "gtest/gtest.h"
#include "clients/sim/dragsim/drag_simulator.h"
#include "server/jobs/job_coordinator.h"
#include "server/mesh/primitive_meshes.h"
#include "storage/sqlite_store.h"
#include "storage/temp_db_dir_for_test.h"
#include "storage/testing/fault_injecting_store.h"

namespace surfmap::testing {

// A callback the test waits for, at most `kCallbackTimeout`.
inline constexpr std::chrono::seconds kCallbackTimeout{20};

template <typename T>
class Awaited {
 public:
  std::function<void(T)> Callback() {
    return [promise = promise_](T value) { promise->set_value(std::move(value)); };
  }
  bool Ready() const { return future_.wait_for(std::chrono::seconds(0)) == std::future_status::ready; }
  // The value, or nullopt (and a test failure naming `what`) after the timeout.
  std::optional<T> Get(const std::string& what) {
    if (future_.wait_for(kCallbackTimeout) != std::future_status::ready) {
      ADD_FAILURE() << what << ": no answer within " << kCallbackTimeout.count() << " s (deadlock or lost callback)";
      return std::nullopt;
    }
    return future_.get();
  }

 private:
  std::shared_ptr<std::promise<T>> promise_ = std::make_shared<std::promise<T>>();
  std::future<T> future_ = promise_->get_future();
};

class CoordinatorFixture : public ::testing::Test {
 protected:
  void SetUp() override { Open(); }
  void TearDown() override { Close(); }

  void Open() {
    absl::StatusOr<std::unique_ptr<SqliteStore>> opened = SqliteStore::Open(dir_.Path("surfmap.db"));
    ASSERT_TRUE(opened.ok()) << opened.status();
    sqlite_ = std::move(*opened);
    faults_ = std::make_unique<FaultInjectingStore>(sqlite_.get());
    completions_ = std::make_unique<TaskQueue>();
    probe_pool_ = std::make_unique<WorkerPool>(2, 1000);
    pool_ = std::make_unique<WorkerPool>(2, 1000);
    coordinator_ = std::make_unique<JobCoordinator>(faults_.get(),
                                                    JobExecutors{completions_.get(), probe_pool_.get(), pool_.get()});
    ASSERT_TRUE(coordinator_->LoadJobs().ok());
  }

  // Stops everything in the order work flows, as surfmapd does.
  void Close() {
    if (!coordinator_) return;
    probe_pool_->Drain();
    pool_->Drain();
    completions_->Drain();
    probe_pool_->Drain();
    pool_->Drain();
    coordinator_.reset();
    faults_.reset();  // delivers what is outstanding
    completions_->Drain();
    probe_pool_.reset();
    pool_.reset();
    completions_.reset();
    sqlite_.reset();
  }

  void Reopen() {
    Close();
    Open();
  }

  // A 200 x 150 mm plate (6 x 4 quads, 35 control vertices) as OBJ text.
  int64_t UploadPlate() {
    absl::StatusOr<ControlMesh> mesh = MakeGridPlate(200, 150, 6, 4);
    EXPECT_TRUE(mesh.ok());
    std::string obj;
    for (const Eigen::Vector3d& p : mesh->positions) absl::StrAppend(&obj, "v ", p.x(), " ", p.y(), " ", p.z(), "\n");
    for (const auto& t : mesh->triangles) absl::StrAppend(&obj, "f ", t[0] + 1, " ", t[1] + 1, " ", t[2] + 1, "\n");
    absl::StatusOr<ObjectRecord> object = coordinator_->UploadObject("plate", MeshFormat::kObj, obj);
    EXPECT_TRUE(object.ok()) << object.status();
    return object.ok() ? object->id : 0;
  }

  // A uniform friction job over the plate's level-0 vertices.
  JobSnapshot CreateUniformJob(int64_t object_id, int budget = 0) {
    JobParams params;
    params.object_id = object_id;
    params.mode = PlanMode::kUniform;
    params.coarsest_level = 0;
    params.finest_level = 1;
    params.budget = budget;
    absl::StatusOr<JobSnapshot> job = coordinator_->CreateJob(params);
    EXPECT_TRUE(job.ok()) << job.status();
    return job.ok() ? *job : JobSnapshot{};
  }

  absl::StatusOr<LeaseOutcome> Lease(int64_t job_id, const std::string& rig) {
    Awaited<absl::StatusOr<LeaseOutcome>> answer;
    coordinator_->probes().LeaseCommand(rig, job_id, answer.Callback());
    std::optional<absl::StatusOr<LeaseOutcome>> got = answer.Get("LeaseCommand");
    if (!got) return absl::DeadlineExceededError("LeaseCommand timed out");
    return *got;
  }

  // A simulated drag on the plate (glass) for the command, seeded by `seed`.
  static DragTrace TraceFor(const LeaseOutcome& lease, uint64_t seed = 1) {
    const ProbeCommand& c = *lease.command;
    const double length = c.probe.segment_length_mm;
    DragGeometry geometry =
        PlaneGeometry(c.position - 0.5 * length * c.drag_direction, c.drag_direction, c.normal, length);
    DragSimOptions options;
    options.seed = seed;
    options.length_mm = length;
    absl::StatusOr<DragSimResult> result = SimulateDrag(geometry, UniformMaterial(kGlass), options);
    EXPECT_TRUE(result.ok()) << result.status();
    return result.ok() ? result->trace : DragTrace{};
  }

  absl::StatusOr<SubmitOutcome> Submit(int64_t command_id, const std::string& rig, const DragTrace& trace,
                                       bool lease_next = false) {
    Awaited<absl::StatusOr<SubmitOutcome>> answer;
    coordinator_->probes().SubmitTrace(
        command_id, rig, [trace]() -> absl::StatusOr<DragTrace> { return trace; }, lease_next, answer.Callback());
    std::optional<absl::StatusOr<SubmitOutcome>> got = answer.Get("SubmitTrace");
    if (!got) return absl::DeadlineExceededError("SubmitTrace timed out");
    return *got;
  }

  absl::StatusOr<JobSnapshot> SetState(int64_t job_id, JobState target) {
    Awaited<absl::StatusOr<JobSnapshot>> answer;
    coordinator_->SetJobState(job_id, target, answer.Callback());
    std::optional<absl::StatusOr<JobSnapshot>> got = answer.Get("SetJobState");
    if (!got) return absl::DeadlineExceededError("SetJobState timed out");
    return *got;
  }

  // Sends the job to be re-read and holds it there: a rig's trace is
  // refused by the store (its lease taken over), which starts the re-read
  // behind a barrier write that is held. Returns that write's number, for
  // faults_->ReleaseWrite; 0 (with a test failure) when it went otherwise.
  int64_t HoldJobInReRead(int64_t job_id) {
    absl::StatusOr<LeaseOutcome> lease = Lease(job_id, "rig-a");
    EXPECT_TRUE(lease.ok() && lease->record) << lease.status();
    if (!lease.ok() || !lease->record) return 0;
    const int64_t trace_write = faults_->writes_submitted() + 1;
    const int64_t reread_barrier = trace_write + 1;  // MarkWriteFailed's SyncAsync
    faults_->FailWrite(trace_write, absl::FailedPreconditionError("command is leased to 'rig-b', not to 'rig-a'"));
    faults_->HoldWrite(reread_barrier);
    absl::StatusOr<SubmitOutcome> refused = Submit(lease->record->id, "rig-a", TraceFor(*lease));
    EXPECT_EQ(refused.status().code(), absl::StatusCode::kFailedPrecondition) << refused.status();
    const bool held = faults_->WaitUntilHeld(reread_barrier, absl::Seconds(10));
    EXPECT_TRUE(held) << "the re-read's barrier write never came";
    return held ? reread_barrier : 0;
  }

  // Leases and measures commands of the job until it completes (or `limit`
  // commands), retrying UNAVAILABLE. Returns the traces acknowledged.
  int MeasureUntilDone(int64_t job_id, const std::string& rig, int limit = 1000) {
    int acked = 0;
    for (int i = 0; i < limit; ++i) {
      absl::StatusOr<LeaseOutcome> lease = Lease(job_id, rig);
      if (!lease.ok()) {
        ADD_FAILURE() << "lease: " << lease.status();
        return acked;
      }
      if (lease->job_finished) return acked;
      if (!lease->record) {
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
        continue;
      }
      const DragTrace trace = TraceFor(*lease, static_cast<uint64_t>(lease->record->id));
      for (int attempt = 0; attempt < 100; ++attempt) {
        absl::StatusOr<SubmitOutcome> outcome = Submit(lease->record->id, rig, trace);
        if (outcome.ok()) {
          ++acked;
          break;
        }
        if (outcome.status().code() != absl::StatusCode::kUnavailable) {
          ADD_FAILURE() << "submit: " << outcome.status();
          return acked;
        }
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
      }
    }
    return acked;
  }

  TempDbDir dir_;
  std::unique_ptr<SqliteStore> sqlite_;
  std::unique_ptr<FaultInjectingStore> faults_;
  std::unique_ptr<TaskQueue> completions_;
  std::unique_ptr<WorkerPool> probe_pool_;
  std::unique_ptr<WorkerPool> pool_;
  std::unique_ptr<JobCoordinator> coordinator_;
};

}  // namespace surfmap::testing
