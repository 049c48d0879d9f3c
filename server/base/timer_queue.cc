#include "server/base/timer_queue.h"

#include <vector>

namespace surfmap {

TimerQueue::TimerQueue() : thread_([this] { Run(); }) {}

TimerQueue::~TimerQueue() {
  {
    MutexLock lock(&mu_);
    stopping_ = true;
  }
  thread_.join();
}

void TimerQueue::RunAt(Clock::time_point when, std::function<void()> task) {
  MutexLock lock(&mu_);
  tasks_.emplace(when, std::move(task));  // the unlock wakes the timer thread
}

void TimerQueue::Run() {
  for (;;) {
    std::vector<std::function<void()>> due;
    {
      MutexLock lock(&mu_);
      mu_.Await([this]() ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu_) { return stopping_ || !tasks_.empty(); });
      if (stopping_) return;
      const Clock::time_point first = tasks_.begin()->first;
      if (first > Clock::now()) {
        // Sleep until the first task is due, or until a task is added (which
        // may be earlier) or the queue stops.
        const size_t count = tasks_.size();
        mu_.AwaitWithTimeout(
            [this, count, first]() ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu_) {
              return stopping_ || tasks_.size() != count || tasks_.begin()->first != first;
            },
            first - Clock::now());
        continue;
      }
      const Clock::time_point now = Clock::now();
      while (!tasks_.empty() && tasks_.begin()->first <= now) {
        due.push_back(std::move(tasks_.begin()->second));
        tasks_.erase(tasks_.begin());
      }
    }
    for (std::function<void()>& task : due) task();
  }
}

}  // namespace surfmap
