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
  // The rigs' work: fitting submitted traces. A pool of its own, so a trace
  // never waits behind a map build or a refit (every trace is short).
  WorkerPool* probes = nullptr;
  // Long work: map builds, refits, job loads, recomputed series, watchers.
  WorkerPool* work = nullptr;
};

}  // namespace surfmap
