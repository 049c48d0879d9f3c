#include "storage/store.h"

#include <future>

namespace surfmap {

// The blocking forms wait on the asynchronous ones, so every implementation
// has a single write path.
absl::StatusOr<std::optional<CommandRecord>> Store::LeaseNextCommand(const LeaseRequest& request) {
  std::promise<absl::StatusOr<std::optional<CommandRecord>>> promise;
  auto future = promise.get_future();
  LeaseNextCommandAsync(request, [&promise](absl::StatusOr<std::optional<CommandRecord>> r) {
    promise.set_value(std::move(r));
  });
  return future.get();
}

absl::StatusOr<AcceptTraceResult> Store::AcceptTrace(AcceptTraceRequest request) {
  std::promise<absl::StatusOr<AcceptTraceResult>> promise;
  auto future = promise.get_future();
  AcceptTraceAsync(std::move(request), [&promise](absl::StatusOr<AcceptTraceResult> r) {
    promise.set_value(std::move(r));
  });
  return future.get();
}

}  // namespace surfmap
