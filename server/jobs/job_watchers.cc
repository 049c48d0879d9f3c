#include "server/jobs/job_watchers.h"

#include <vector>

namespace surfmap {

int64_t AddListener(JobRuntime& runtime, std::function<void()> listener) {
  MutexLock lock(&runtime.watchers_mu);
  const int64_t id = runtime.next_listener_id++;
  runtime.listeners[id] = std::move(listener);
  return id;
}

void RemoveListener(JobRuntime& runtime, int64_t handle) {
  MutexLock lock(&runtime.watchers_mu);
  runtime.listeners.erase(handle);
}

void NotifyListeners(JobRuntime& runtime) {
  std::vector<std::function<void()>> listeners;
  {
    MutexLock lock(&runtime.watchers_mu);
    ++runtime.update_revision;
    listeners.reserve(runtime.listeners.size());
    for (const auto& [id, listener] : runtime.listeners) listeners.push_back(listener);
  }
  for (const std::function<void()>& listener : listeners) listener();
}

int64_t UpdateRevision(JobRuntime& runtime) {
  MutexLock lock(&runtime.watchers_mu);
  return runtime.update_revision;
}

}  // namespace surfmap
