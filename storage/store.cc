#include "storage/store.h"

#include <future>

namespace surfmap {
namespace {

// Runs an asynchronous store call and waits for its callback.
template <typename T, typename Call>
absl::StatusOr<T> Wait(Call call) {
  std::promise<absl::StatusOr<T>> promise;
  auto future = promise.get_future();
  call([&promise](absl::StatusOr<T> r) { promise.set_value(std::move(r)); });
  return future.get();
}

}  // namespace

// The blocking forms wait on the asynchronous ones, so every implementation
// has a single write path. Never call them from a store callback.
absl::StatusOr<std::optional<CommandRecord>> Store::LeaseNextCommand(const LeaseRequest& request) {
  return Wait<std::optional<CommandRecord>>([&](LeaseCallback done) { LeaseNextCommandAsync(request, std::move(done)); });
}

absl::StatusOr<AcceptTraceResult> Store::AcceptTrace(AcceptTraceRequest request) {
  return Wait<AcceptTraceResult>(
      [&](AcceptTraceCallback done) { AcceptTraceAsync(std::move(request), std::move(done)); });
}

absl::StatusOr<JobRecord> Store::UpdateJobState(JobStateChange change) {
  return Wait<JobRecord>([&](JobCallback done) { UpdateJobStateAsync(std::move(change), std::move(done)); });
}

}  // namespace surfmap
