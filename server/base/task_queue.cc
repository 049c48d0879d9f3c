#include "server/base/task_queue.h"

namespace surfmap {

TaskQueue::TaskQueue() : thread_([this] { Run(); }) {}

TaskQueue::~TaskQueue() {
  {
    absl::MutexLock lock(&mu_);
    stopping_ = true;
  }
  thread_.join();
}

void TaskQueue::Post(std::function<void()> task) {
  {
    absl::MutexLock lock(&mu_);
    if (!stopping_) {
      queue_.push_back(std::move(task));
      ++posted_;
      return;
    }
  }
  task();
}

void TaskQueue::Drain() {
  absl::MutexLock lock(&mu_);
  const int64_t target = posted_;
  auto caught_up = [this, target]() ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu_) { return completed_ >= target; };
  mu_.Await(absl::Condition(&caught_up));
}

int64_t TaskQueue::completed() const {
  absl::MutexLock lock(&mu_);
  return completed_;
}

void TaskQueue::Run() {
  for (;;) {
    std::function<void()> task;
    {
      absl::MutexLock lock(&mu_);
      mu_.Await(absl::Condition(this, &TaskQueue::HasTaskOrStopping));
      if (queue_.empty()) return;  // stopping and drained
      task = std::move(queue_.front());
      queue_.pop_front();
    }
    task();
    absl::MutexLock lock(&mu_);
    ++completed_;
  }
}

}  // namespace surfmap
