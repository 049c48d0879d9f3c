#include "server/base/timer_queue.h"

#include <atomic>
#include <vector>

#include "gtest/gtest.h"
#include "server/base/mutex.h"

namespace surfmap {
namespace {

using Clock = TimerQueue::Clock;
using std::chrono::milliseconds;

TEST(TimerQueue, RunsTasksNoSoonerThanAskedAndInTimeOrder) {
  TimerQueue timers;
  Mutex mu;
  std::vector<int> order;
  std::vector<Clock::duration> late;
  Notification done;
  const Clock::time_point start = Clock::now();
  // Added out of order: 60 ms, 20 ms, 40 ms.
  for (int delay : {60, 20, 40}) {
    timers.RunAt(start + milliseconds(delay), [&, delay] {
      MutexLock lock(&mu);
      order.push_back(delay);
      late.push_back(Clock::now() - (start + milliseconds(delay)));
      if (order.size() == 3) done.Notify();
    });
  }
  ASSERT_TRUE(done.WaitForNotificationWithTimeout(std::chrono::seconds(10)));
  MutexLock lock(&mu);
  EXPECT_EQ(order, (std::vector<int>{20, 40, 60}));
  for (Clock::duration d : late) EXPECT_GE(d, Clock::duration::zero()) << "a task ran early";
}

TEST(TimerQueue, AnEarlierTaskAddedWhileWaitingRunsFirst) {
  TimerQueue timers;
  std::atomic<int> first{0};
  Notification done;
  timers.RunAt(Clock::now() + std::chrono::seconds(5), [&] {
    if (first.load() == 0) first = 2;
  });
  timers.RunAt(Clock::now() + milliseconds(10), [&] {
    if (first.load() == 0) first = 1;
    done.Notify();
  });
  ASSERT_TRUE(done.WaitForNotificationWithTimeout(std::chrono::seconds(2))) << "waited for the later task";
  EXPECT_EQ(first.load(), 1);
}

TEST(TimerQueue, APastTimeRunsAtOnce) {
  TimerQueue timers;
  Notification done;
  timers.RunAt(Clock::now() - std::chrono::seconds(1), [&] { done.Notify(); });
  EXPECT_TRUE(done.WaitForNotificationWithTimeout(std::chrono::seconds(2)));
}

}  // namespace
}  // namespace surfmap
