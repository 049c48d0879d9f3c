#include "server/base/task_queue.h"

#include <atomic>
#include <vector>

#include "server/base/mutex.h"
#include "gtest/gtest.h"

namespace surfmap {
namespace {

TEST(TaskQueue, RunsTasksInPostOrderOnOneThread) {
  std::vector<int> order;
  std::thread::id runner;
  bool one_thread = true;
  {
    TaskQueue queue;
    for (int i = 0; i < 1000; ++i) {
      queue.Post([&, i] {
        if (i == 0) runner = std::this_thread::get_id();
        one_thread = one_thread && std::this_thread::get_id() == runner;
        order.push_back(i);  // only the queue's thread touches it
      });
    }
    queue.Drain();
    EXPECT_EQ(queue.completed(), 1000);
  }
  ASSERT_EQ(order.size(), 1000u);
  for (int i = 0; i < 1000; ++i) EXPECT_EQ(order[i], i);
  EXPECT_TRUE(one_thread);
  EXPECT_NE(runner, std::this_thread::get_id());
}

TEST(TaskQueue, PostNeverWaitsForARunningTask) {
  TaskQueue queue;
  Notification release;
  queue.Post([&] { release.WaitForNotification(); });
  std::atomic<int> ran{0};
  for (int i = 0; i < 100; ++i) queue.Post([&] { ran.fetch_add(1); });  // returns while the first blocks
  EXPECT_EQ(ran.load(), 0);
  release.Notify();
  queue.Drain();
  EXPECT_EQ(ran.load(), 100);
}

TEST(TaskQueue, DestructionRunsEveryPostedTask) {
  std::atomic<int> ran{0};
  {
    TaskQueue queue;
    for (int i = 0; i < 50; ++i) queue.Post([&] { ran.fetch_add(1); });
  }
  EXPECT_EQ(ran.load(), 50);
}

}  // namespace
}  // namespace surfmap
