#include "server/base/task_queue.h"

namespace surfmap {

TaskQueue::TaskQueue() : thread_([this] { Run(); }) {}

TaskQueue::~TaskQueue() {
  {
    MutexLock lock(&mu_);
    stopping_ = true;
  }
  thread_.join();
}

void TaskQueue::Post(std::function<void()> task) {
  {
    MutexLock lock(&mu_);
    if (!stopping_) {
      queue_.push_back(std::move(task));
      ++posted_;
      return;
    }
  }
  task();
}

void TaskQueue::Drain() {
  MutexLock lock(&mu_);
  const int64_t target = posted_;
  auto caught_up = [this, target]() ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu_) { return completed_ >= target; };
  mu_.Await(caught_up);
}

int64_t TaskQueue::completed() const {
  MutexLock lock(&mu_);
  return completed_;
}

void TaskQueue::Run() {
  for (;;) {
    std::function<void()> task;
    {
      MutexLock lock(&mu_);
      mu_.Await([this]() ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu_) { return HasTaskOrStopping(); });
      if (queue_.empty()) return;  // stopping and drained
      task = std::move(queue_.front());
      queue_.pop_front();
    }
    task();
    MutexLock lock(&mu_);
    ++completed_;
  }
}

}  // namespace surfmap
