#include "server/base/mutex.h"

#include <atomic>
#include <chrono>
#include <future>
#include <thread>

#include "gtest/gtest.h"

namespace surfmap {
namespace {

// Long enough that only a lost wakeup (or a deadlock) runs into it.
constexpr std::chrono::seconds kLostWakeup{20};

// A waiter that changes what another waiter waits for and then waits itself
// releases the lock inside the condition variable, not through Unlock().
// Found in the fault-injecting store: it marked a write held and waited for
// its release, and a test waiting to see the write held slept until its own
// timeout.
TEST(MutexTest, AWaitWakesWhoeverWaitsForWhatTheWaiterChangedFirst) {
  Mutex mu;
  bool second_waiting = false;
  bool go = false;
  std::atomic<bool> first_about_to_wait{false};

  std::future<void> first = std::async(std::launch::async, [&] {
    MutexLock lock(&mu);
    first_about_to_wait = true;
    mu.Await([&]() { return second_waiting; });
    go = true;
  });
  while (!first_about_to_wait) std::this_thread::yield();
  // The first thread holds the lock until it waits; the second one starts
  // once it is waiting (or has already seen the flag: then the test passes
  // either way).
  std::future<void> second = std::async(std::launch::async, [&] {
    MutexLock lock(&mu);
    second_waiting = true;  // what the first waits for ...
    mu.Await([&]() { return go; });  // ... and then wait
  });

  const bool first_done = first.wait_for(kLostWakeup) == std::future_status::ready;
  const bool second_done = second.wait_for(kLostWakeup) == std::future_status::ready;
  if (!first_done || !second_done) {
    MutexLock lock(&mu);  // let both finish, so the test fails instead of hanging
    second_waiting = go = true;
  }
  EXPECT_TRUE(first_done) << "the first waiter was never woken when the second changed its condition and waited";
  EXPECT_TRUE(second_done);
}

TEST(MutexTest, AwaitWithTimeoutReturnsTheConditionAtTheEnd) {
  Mutex mu;
  MutexLock lock(&mu);
  EXPECT_FALSE(mu.AwaitWithTimeout([] { return false; }, std::chrono::milliseconds(1)));
  EXPECT_TRUE(mu.AwaitWithTimeout([] { return true; }, std::chrono::milliseconds(1)));
}

}  // namespace
}  // namespace surfmap
