// What every RPC handler shares, and the few steps every handler takes: admit
// the caller through the RequestGate, run the work (inline when it is cheap,
// on the pool when it is long, or asynchronously), finish with a status
// converted in one place. A handler never blocks its gRPC thread.
#pragma once

#include <functional>
#include <string>

#include <grpcpp/grpcpp.h>
#include <spdlog/spdlog.h>
#include "absl/status/status.h"
#include "server/base/timer_queue.h"
#include "server/base/worker_pool.h"
#include "server/jobs/job_coordinator.h"
#include "server/service/request_gate.h"
#include "server/service/server_config.h"
#include "server/service/status_conversion.h"

namespace surfmap {

struct ServiceContext {
  JobCoordinator* coordinator = nullptr;
  const RequestGate* gate = nullptr;
  const ServerConfig* config = nullptr;
  WorkerPool* pool = nullptr;    // long work
  TimerQueue* timers = nullptr;  // delayed posts (watch streams' update pacing)
  class WatchUpdateCache* watch_updates = nullptr;  // updates shared by the streams of a job
};

// Finishes `reactor` with `status`, logging failures (client errors at debug,
// server errors at warn).
void FinishUnary(grpc::ServerUnaryReactor* reactor, const char* method, const absl::Status& status);

// The gate's answer for a call (RequestGate::Admit); a refusal is logged at
// warn with the method, the peer and why, never the token. Every handler
// admits through here, unary or streaming.
absl::Status AdmitCall(const grpc::ServerContextBase& context, const ServiceContext& services, Role needed,
                       const char* method);

// Cheap work (memory, one indexed read): run inline, then finish.
grpc::ServerUnaryReactor* HandleUnary(grpc::CallbackServerContext* context, const ServiceContext& services,
                                      Role needed, const char* method, const std::function<absl::Status()>& work);

// Long work: runs on the worker pool; UNAVAILABLE when the pool's queue is full.
grpc::ServerUnaryReactor* HandleUnaryOnPool(grpc::CallbackServerContext* context, const ServiceContext& services,
                                            Role needed, const char* method, std::function<absl::Status()> work);

// Inline when `cheap`, else on the pool (e.g. a job that is in memory or not).
grpc::ServerUnaryReactor* HandleUnaryInlineIf(bool cheap, grpc::CallbackServerContext* context,
                                              const ServiceContext& services, Role needed, const char* method,
                                              std::function<absl::Status()> work);

// Asynchronous work: `start` runs inline and must not block; it calls
// `finish` exactly once, from any thread, when the work is done.
using FinishFn = std::function<void(absl::Status)>;
grpc::ServerUnaryReactor* HandleUnaryAsync(grpc::CallbackServerContext* context, const ServiceContext& services,
                                           Role needed, const char* method,
                                           const std::function<void(FinishFn finish)>& start);

// A server stream refused before it started: finish it, it deletes itself.
template <typename Message>
class RefusedStream final : public grpc::ServerWriteReactor<Message> {
 public:
  void OnDone() override { delete this; }
};

}  // namespace surfmap
