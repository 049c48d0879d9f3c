// TaskQueue: one thread that runs posted tasks one after another, in the
// order they were posted. Unbounded: it is for continuations whose number is
// bounded by the requests in flight (store write completions), never for
// new work a client can create at will (that goes to a WorkerPool).
//
// The job coordinator posts every store callback here: callbacks then run in
// commit order, off the store's writer thread, and may take job locks.
#pragma once

#include <deque>
#include <functional>
#include <string>
#include <thread>

#include "absl/base/thread_annotations.h"
#include "server/base/mutex.h"

namespace surfmap {

class TaskQueue {
 public:
  TaskQueue();
  // Runs every task posted before, then stops the thread.
  ~TaskQueue();
  TaskQueue(const TaskQueue&) = delete;
  TaskQueue& operator=(const TaskQueue&) = delete;

  // Never blocks. After destruction began the task is run on the caller's
  // thread (nothing is dropped).
  void Post(std::function<void()> task) ABSL_LOCKS_EXCLUDED(mu_);

  // Blocks until every task posted before this call has run. Not from a task.
  void Drain() ABSL_LOCKS_EXCLUDED(mu_);

  // Tasks run so far (for tests).
  int64_t completed() const ABSL_LOCKS_EXCLUDED(mu_);

 private:
  void Run();
  bool HasTaskOrStopping() const ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu_) { return stopping_ || !queue_.empty(); }

  mutable Mutex mu_;
  std::deque<std::function<void()>> queue_ ABSL_GUARDED_BY(mu_);
  bool stopping_ ABSL_GUARDED_BY(mu_) = false;
  int64_t posted_ ABSL_GUARDED_BY(mu_) = 0;
  int64_t completed_ ABSL_GUARDED_BY(mu_) = 0;
  std::thread thread_;  // last: starts after the members above exist
};

}  // namespace surfmap
