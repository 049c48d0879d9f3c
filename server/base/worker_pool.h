// WorkerPool: a fixed set of threads for long work (trace fits, map builds,
// refits, mesh refinement, recomputed series), so gRPC's callback threads and
// the store's writer never run it. Two ways in:
//   Submit: new work a client asked for. Bounded: when `max_queued` tasks
//           wait, it refuses, and the caller answers UNAVAILABLE.
//   Post:   the continuation of work already admitted (a reply to build after
//           a durable write). Always accepted: refusing it would strand a
//           request that was already taken on; its number is bounded by the
//           requests in flight.
#pragma once

#include <cstddef>
#include <deque>
#include <functional>
#include <thread>
#include <vector>

#include "absl/base/thread_annotations.h"
#include "server/base/mutex.h"

namespace surfmap {

class WorkerPool {
 public:
  WorkerPool(int threads, size_t max_queued);
  ~WorkerPool();  // runs the queued work, then joins
  WorkerPool(const WorkerPool&) = delete;
  WorkerPool& operator=(const WorkerPool&) = delete;

  // False when `max_queued` tasks wait or the pool is shutting down.
  bool Submit(std::function<void()> work) ABSL_LOCKS_EXCLUDED(mu_);
  // Always queued (run on the caller's thread once the pool is shutting down).
  void Post(std::function<void()> work) ABSL_LOCKS_EXCLUDED(mu_);
  // Blocks until the queue is empty and no task runs. Not from a task.
  void Drain() ABSL_LOCKS_EXCLUDED(mu_);

  int threads() const { return static_cast<int>(threads_.size()); }

 private:
  void Run();
  bool HasWorkOrStopping() const ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu_) { return stopping_ || !queue_.empty(); }
  bool Idle() const ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu_) { return queue_.empty() && running_ == 0; }

  Mutex mu_;
  std::deque<std::function<void()>> queue_ ABSL_GUARDED_BY(mu_);
  const size_t max_queued_;
  bool stopping_ ABSL_GUARDED_BY(mu_) = false;
  int running_ ABSL_GUARDED_BY(mu_) = 0;
  std::vector<std::thread> threads_;
};

}  // namespace surfmap
