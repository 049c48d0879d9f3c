// What every RPC handler shares, and the few steps every handler takes: admit
// the caller through the RequestGate, run the work (inline or on the pool),
// finish with a status converted in one place.
#pragma once

#include <functional>
#include <string>

#include <grpcpp/grpcpp.h>
#include <spdlog/spdlog.h>
#include "absl/status/status.h"
#include "server/jobs/job_coordinator.h"
#include "server/service/request_gate.h"
#include "server/service/server_config.h"
#include "server/service/status_conversion.h"
#include "server/service/worker_pool.h"

namespace surfmap {

struct ServiceContext {
  JobCoordinator* coordinator = nullptr;
  const RequestGate* gate = nullptr;
  const ServerConfig* config = nullptr;
  WorkerPool* pool = nullptr;
};

// Finishes `reactor` with `status`, logging failures (client errors at debug,
// server errors at warn).
void FinishUnary(grpc::ServerUnaryReactor* reactor, const char* method, const absl::Status& status);

// The common shape of a unary handler: admit, then run `work` inline (fast
// calls) and finish with its status.
grpc::ServerUnaryReactor* HandleUnary(grpc::CallbackServerContext* context, const ServiceContext& services,
                                      Role needed, const char* method, const std::function<absl::Status()>& work);

// Same, but `work` runs on the worker pool (long calls); UNAVAILABLE when the
// pool's queue is full.
grpc::ServerUnaryReactor* HandleUnaryOnPool(grpc::CallbackServerContext* context, const ServiceContext& services,
                                            Role needed, const char* method, std::function<absl::Status()> work);

}  // namespace surfmap
