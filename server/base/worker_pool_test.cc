#include "server/base/worker_pool.h"

#include <atomic>

#include "server/base/mutex.h"
#include "gtest/gtest.h"

namespace surfmap {
namespace {

TEST(WorkerPool, SubmitRefusesWhenTheQueueIsFullButPostAlwaysQueues) {
  WorkerPool pool(1, /*max_queued=*/2);
  Notification started, release;
  ASSERT_TRUE(pool.Submit([&] {
    started.Notify();
    release.WaitForNotification();
  }));
  started.WaitForNotification();  // the only thread is busy; the queue is empty
  std::atomic<int> ran{0};
  EXPECT_TRUE(pool.Submit([&] { ran.fetch_add(1); }));
  EXPECT_TRUE(pool.Submit([&] { ran.fetch_add(1); }));
  EXPECT_FALSE(pool.Submit([&] { ran.fetch_add(1); })) << "a third waiting task exceeds max_queued = 2";
  pool.Post([&] { ran.fetch_add(10); });  // a continuation is never refused
  release.Notify();
  pool.Drain();
  EXPECT_EQ(ran.load(), 12);
}

TEST(WorkerPool, DrainWaitsForRunningTasks) {
  WorkerPool pool(2, 100);
  std::atomic<int> done{0};
  for (int i = 0; i < 20; ++i) {
    ASSERT_TRUE(pool.Submit([&] {
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
      done.fetch_add(1);
    }));
  }
  pool.Drain();
  EXPECT_EQ(done.load(), 20);
}

TEST(WorkerPool, DestructionRunsQueuedWork) {
  std::atomic<int> done{0};
  {
    WorkerPool pool(1, 100);
    for (int i = 0; i < 10; ++i) ASSERT_TRUE(pool.Submit([&] { done.fetch_add(1); }));
  }
  EXPECT_EQ(done.load(), 10);
}

}  // namespace
}  // namespace surfmap
