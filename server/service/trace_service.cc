#include "absl/strings/str_cat.h"
#include "server/jobs/stored_trace.h"
#include "server/service/grpc_services.h"
#include "server/service/proto_conversion.h"

namespace surfmap {

grpc::ServerUnaryReactor* TraceServiceImpl::GetTrace(grpc::CallbackServerContext* context,
                                                     const pb::GetTraceRequest* request,
                                                     pb::GetTraceResponse* response) {
  // Every sample of a trace: a bulk read and an O(samples) conversion, on the pool.
  return HandleUnaryOnPool(context, s_, Role::kRead, "GetTrace", [this, request, response]() -> absl::Status {
    absl::StatusOr<TraceRecord> trace = s_.coordinator->reads().GetTrace(request->trace_id());
    if (!trace.ok()) return trace.status();
    response->set_trace_id(trace->id);
    response->set_command_id(trace->command_id);
    response->set_job_id(trace->job_id);
    *response->mutable_samples() = DragTraceToProto(FromStoredSamples(trace->samples));
    return absl::OkStatus();
  });
}

grpc::ServerUnaryReactor* TraceServiceImpl::RefitJob(grpc::CallbackServerContext* context,
                                                     const pb::RefitJobRequest* request,
                                                     pb::RefitJobResponse* response) {
  return HandleUnaryOnPool(context, s_, Role::kSteer, "RefitJob", [this, request, response]() -> absl::Status {
    absl::StatusOr<FitOptions> options = FitOptionsFromProto(request->settings());
    if (!options.ok()) return options.status();
    absl::StatusOr<RefitOutcome> outcome = s_.coordinator->RefitJob(request->job_id(), *options);
    if (!outcome.ok()) return outcome.status();
    response->set_fit_version(outcome->version);
    response->set_refitted(outcome->refitted);
    response->set_failed(outcome->failed);
    spdlog::info("rpc=RefitJob job_id={} version={} refitted={} failed={}", request->job_id(), outcome->version,
                 outcome->refitted, outcome->failed);
    return absl::OkStatus();
  });
}

}  // namespace surfmap
