// The listeners of a job (WatchJob streams). A listener must not block: it
// sets a flag and posts its work (see JobWatchReactor). Listeners are called
// with no lock held, from the completion queue or a pool thread, never from
// the store's writer thread.
#pragma once

#include <cstdint>
#include <functional>

#include "server/jobs/job_runtime.h"

namespace surfmap {

// Returns a handle for RemoveListener.
int64_t AddListener(JobRuntime& runtime, std::function<void()> listener);
void RemoveListener(JobRuntime& runtime, int64_t handle);
// Bumps the job's update revision, then calls every listener. Call without
// holding any of the job's locks.
void NotifyListeners(JobRuntime& runtime);
int64_t UpdateRevision(JobRuntime& runtime);

}  // namespace surfmap
