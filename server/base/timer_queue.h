// TimerQueue: runs tasks at given times on one thread of its own. For short
// tasks that post real work elsewhere (e.g. "build this stream's next update
// on the pool, no sooner than 250 ms after the last one"), never for the work
// itself.
#pragma once

#include <chrono>
#include <functional>
#include <map>
#include <thread>

#include "absl/base/thread_annotations.h"
#include "server/base/mutex.h"

namespace surfmap {

class TimerQueue {
 public:
  using Clock = std::chrono::steady_clock;

  TimerQueue();
  // Runs the tasks that are due now; drops the others (their owners are
  // shutting down too).
  ~TimerQueue();
  TimerQueue(const TimerQueue&) = delete;
  TimerQueue& operator=(const TimerQueue&) = delete;

  // Runs `task` on the timer thread at `when` (at once if it has passed).
  // Tasks due at the same time run in the order they were added.
  void RunAt(Clock::time_point when, std::function<void()> task) ABSL_LOCKS_EXCLUDED(mu_);

 private:
  void Run();

  Mutex mu_;
  std::multimap<Clock::time_point, std::function<void()>> tasks_ ABSL_GUARDED_BY(mu_);
  bool stopping_ ABSL_GUARDED_BY(mu_) = false;
  std::thread thread_;  // last
};

}  // namespace surfmap
