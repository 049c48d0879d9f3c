#include "storage/testing/fault_injecting_store.h"

#include <atomic>
#include <future>
#include <thread>

#include "gtest/gtest.h"
#include "storage/sqlite_store.h"
#include "storage/store_test_support_for_test.h"
#include "storage/temp_db_dir_for_test.h"

namespace surfmap {
namespace {

class FaultInjectingStoreTest : public ::testing::Test {
 protected:
  void SetUp() override {
    absl::StatusOr<std::unique_ptr<SqliteStore>> opened = SqliteStore::Open(dir_.Path("surfmap.db"));
    ASSERT_TRUE(opened.ok()) << opened.status();
    sqlite_ = std::move(*opened);
    store_ = std::make_unique<FaultInjectingStore>(sqlite_.get());
    absl::StatusOr<CreatedJob> job = MakeTestJob(*store_, 10);  // writes 1 (object) and 2 (job)
    ASSERT_TRUE(job.ok()) << job.status();
    job_ = *job;
  }
  void TearDown() override {
    store_.reset();  // before the wrapped store
    sqlite_.reset();
  }

  LeaseRequest Lease(const std::string& rig) const { return LeaseRequest{job_.job.id, rig, 1'000, 60'000}; }

  TempDbDir dir_;
  std::unique_ptr<SqliteStore> sqlite_;
  std::unique_ptr<FaultInjectingStore> store_;
  CreatedJob job_;
};

TEST_F(FaultInjectingStoreTest, AnInjectedFailureNeverReachesTheWrappedStore) {
  store_->FailWrite(3, absl::UnavailableError("disk on fire"));
  absl::StatusOr<std::optional<CommandRecord>> failed = store_->LeaseNextCommand(Lease("rig-a"));
  EXPECT_EQ(failed.status().code(), absl::StatusCode::kUnavailable);
  EXPECT_EQ(sqlite_->CountLeasedCommands(job_.job.id, 1'000)->total, 0) << "write 3 must not have happened";
  absl::StatusOr<std::optional<CommandRecord>> next = store_->LeaseNextCommand(Lease("rig-a"));
  ASSERT_TRUE(next.ok() && next->has_value()) << next.status();
  EXPECT_EQ(store_->writes_submitted(), 4);
}

TEST_F(FaultInjectingStoreTest, AHeldWriteHoldsBackEveryLaterWriteInOrder) {
  store_->HoldWrite(3);
  std::vector<int> order;
  std::mutex order_mu;
  for (int i = 0; i < 3; ++i) {
    store_->LeaseNextCommandAsync(Lease("rig"), [&, i](absl::StatusOr<std::optional<CommandRecord>> r) {
      EXPECT_TRUE(r.ok());
      std::lock_guard<std::mutex> lock(order_mu);
      order.push_back(i);
    });
  }
  ASSERT_TRUE(store_->WaitUntilHeld(3, absl::Seconds(10)));
  std::this_thread::sleep_for(std::chrono::milliseconds(50));
  {
    std::lock_guard<std::mutex> lock(order_mu);
    EXPECT_TRUE(order.empty()) << "writes 4 and 5 overtook the held write 3";
  }
  store_->ReleaseWrite(3);
  std::promise<void> synced;
  store_->SyncAsync([&](absl::Status) { synced.set_value(); });
  synced.get_future().wait();
  std::lock_guard<std::mutex> lock(order_mu);
  EXPECT_EQ(order, (std::vector<int>{0, 1, 2}));
}

TEST_F(FaultInjectingStoreTest, InlineDeliveryRunsTheCallbackOnTheCallingThreadBeforeReturning) {
  store_->SetCallbackDelivery(FaultInjectingStore::CallbackDelivery::kInline);
  std::thread::id callback_thread;
  bool called = false;
  store_->LeaseNextCommandAsync(Lease("rig"), [&](absl::StatusOr<std::optional<CommandRecord>>) {
    callback_thread = std::this_thread::get_id();
    called = true;
  });
  EXPECT_TRUE(called);
  EXPECT_EQ(callback_thread, std::this_thread::get_id());
}

TEST_F(FaultInjectingStoreTest, LateDeliveryRunsTheCallbackOnAnotherThreadAfterTheDelay) {
  store_->SetCallbackDelivery(FaultInjectingStore::CallbackDelivery::kLate, absl::Milliseconds(30));
  std::promise<std::thread::id> callback_thread;
  const absl::Time start = absl::Now();
  store_->LeaseNextCommandAsync(Lease("rig"), [&](absl::StatusOr<std::optional<CommandRecord>>) {
    callback_thread.set_value(std::this_thread::get_id());
  });
  EXPECT_NE(callback_thread.get_future().get(), std::this_thread::get_id());
  EXPECT_GE(absl::Now() - start, absl::Milliseconds(30));
}

TEST_F(FaultInjectingStoreTest, ABrokenDiskFailsEveryWriteUntilHealed) {
  store_->FailWritesFrom(3, absl::UnavailableError("I/O error"));
  EXPECT_FALSE(store_->LeaseNextCommand(Lease("a")).ok());
  EXPECT_FALSE(store_->UpdateJobState(JobStateChange{job_.job.id, JobState::kPaused, {}}).ok());
  store_->HealWrites();
  EXPECT_TRUE(store_->UpdateJobState(JobStateChange{job_.job.id, JobState::kPaused, {}}).ok());
}

}  // namespace
}  // namespace surfmap
