// Where the job layer runs what it does not run on the caller's thread.
#pragma once

#include "server/base/task_queue.h"
#include "server/base/worker_pool.h"

namespace surfmap {

struct JobExecutors {
  // Store write completions, in commit order: every store callback is posted
  // here and does nothing else on the store's thread. Tasks are short (apply
  // a committed write to memory, notify watchers, answer the caller).
  TaskQueue* completions = nullptr;
  // Short work that must not wait behind long work: fitting the rigs'
  // submitted traces, and the store read that completes a steering answer.
  // A pool of its own, so neither waits behind a map build or a refit
  // (every task here is short).
  WorkerPool* probes = nullptr;
  // Long work: map builds, refits, job loads, recomputed series, watchers.
  WorkerPool* work = nullptr;
};

}  // namespace surfmap
