#include "absl/strings/str_cat.h"
#include "server/codec/rig_registration_proto.h"
#include "server/jobs/stored_trace.h"
#include "server/service/provenance_proto.h"
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
    FillMetadata(trace->metadata_json, trace->received_unix_ms, response->mutable_provenance(),
                 response->mutable_import());
    if (response->import().source().empty()) response->clear_import();  // a leased trace
    absl::StatusOr<TraceFrameRecord> frame = s_.coordinator->reads().GetTraceFrame(trace->id);
    if (!frame.ok()) return frame.status();
    // A frame this build does not know is a damaged row, as the refit
    // (StoredTraceInObjectFrame) says for it, never silently the object's.
    absl::StatusOr<TraceFrame> parsed = ParseTraceFrame(frame->frame);
    if (!parsed.ok()) {
      return absl::DataLossError(
          absl::StrCat("trace ", trace->id, ": stored frame: ", parsed.status().message()));
    }
    response->set_frame(TraceFrameToProto(*parsed));
    response->set_registration_id(frame->registration_id);
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

namespace {

absl::StatusOr<pb::RejectedTrace> RejectedTraceToProto(const RejectedTraceRecord& r) {
  pb::RejectedTrace out;
  out.set_rejected_trace_id(r.id);
  out.set_command_id(r.command_id);
  out.set_job_id(r.job_id);
  out.set_rig_id(r.rig_id);
  out.set_check(r.check_name);
  out.set_message(r.message);
  out.set_sample_count(r.n_samples);
  *out.mutable_received() = TimestampFromUnixMs(r.received_unix_ms);
  absl::StatusOr<TraceFrame> frame = ParseTraceFrame(r.frame);
  if (!frame.ok()) {
    return absl::DataLossError(absl::StrCat("rejected trace ", r.id, ": stored frame: ", frame.status().message()));
  }
  out.set_frame(TraceFrameToProto(*frame));
  out.set_registration_id(r.registration_id);
  return out;
}

}  // namespace

grpc::ServerUnaryReactor* TraceServiceImpl::ListRejectedTraces(grpc::CallbackServerContext* context,
                                                               const pb::ListRejectedTracesRequest* request,
                                                               pb::ListRejectedTracesResponse* response) {
  return HandleUnaryOnPool(context, s_, Role::kRead, "ListRejectedTraces", [this, request, response]() -> absl::Status {
    absl::StatusOr<std::vector<RejectedTraceRecord>> rejected =
        s_.coordinator->reads().ListRejectedTraces(request->job_id());
    if (!rejected.ok()) return rejected.status();
    for (const RejectedTraceRecord& r : *rejected) {
      absl::StatusOr<pb::RejectedTrace> proto = RejectedTraceToProto(r);
      if (!proto.ok()) return proto.status();
      *response->add_rejected_traces() = *std::move(proto);
    }
    return absl::OkStatus();
  });
}

grpc::ServerUnaryReactor* TraceServiceImpl::GetRejectedTrace(grpc::CallbackServerContext* context,
                                                             const pb::GetRejectedTraceRequest* request,
                                                             pb::GetRejectedTraceResponse* response) {
  return HandleUnaryOnPool(context, s_, Role::kRead, "GetRejectedTrace", [this, request, response]() -> absl::Status {
    absl::StatusOr<RejectedTraceRecord> rejected =
        s_.coordinator->reads().GetRejectedTrace(request->rejected_trace_id());
    if (!rejected.ok()) return rejected.status();
    absl::StatusOr<pb::RejectedTrace> proto = RejectedTraceToProto(*rejected);
    if (!proto.ok()) return proto.status();
    *response->mutable_rejected_trace() = *std::move(proto);
    *response->mutable_rejected_trace()->mutable_samples() = DragTraceToProto(FromStoredSamples(rejected->samples));
    return absl::OkStatus();
  });
}

}  // namespace surfmap
