#include "absl/strings/str_cat.h"
#include "server/service/grpc_services.h"
#include "server/service/proto_builders.h"
#include "server/service/proto_conversion.h"

namespace surfmap {
namespace {

absl::Status ValidateRigId(const std::string& rig_id) {
  if (rig_id.empty() || rig_id.size() > 100) return absl::InvalidArgumentError("rig_id must have 1..100 characters");
  return absl::OkStatus();
}

google::protobuf::Duration DurationFromMs(int64_t ms) {
  google::protobuf::Duration d;
  d.set_seconds(ms / 1000);
  d.set_nanos(static_cast<int32_t>((ms % 1000) * 1'000'000));
  return d;
}

// A lease outcome as the API's answer (LeaseCommand, or SubmitTrace's `next`).
void FillLeaseResponse(const LeaseOutcome& outcome, pb::LeaseCommandResponse* response) {
  response->set_job_finished(outcome.job_finished);
  if (outcome.command) {
    const CommandRecord& record = *outcome.record;
    const ProbeCommand& c = *outcome.command;
    pb::ProbeCommand* out = response->mutable_command();
    out->set_command_id(record.id);
    out->set_job_id(record.job_id);
    out->mutable_site()->set_level(c.site.level);
    out->mutable_site()->set_vertex(c.site.vertex);
    *out->mutable_position() = ToProto(c.position);
    *out->mutable_normal() = ToProto(c.normal);
    *out->mutable_drag_direction() = ToProto(c.drag_direction);
    out->mutable_probe()->set_segment_length_mm(c.probe.segment_length_mm);
    out->mutable_probe()->set_speed_mm_s(c.probe.speed_mm_per_s);
    out->mutable_probe()->set_normal_force_n(c.probe.normal_force_n);
    out->set_attempt(record.attempt);
    *out->mutable_lease_deadline() = TimestampFromUnixMs(record.lease_deadline_unix_ms);
  } else if (!outcome.job_finished) {
    *response->mutable_retry_after() = DurationFromMs(outcome.retry_after_ms);
  }
}

// SubmitTraceStream: chunks are concatenated; the first names the command.
class SubmitStreamReactor final : public grpc::ServerReadReactor<pb::SubmitTraceChunk> {
 public:
  SubmitStreamReactor(ProbeServiceImpl* service, const ServiceContext& s, pb::SubmitTraceResponse* response)
      : service_(service), s_(s), response_(response) {}

  void Start() { StartRead(&chunk_); }

  void OnReadDone(bool ok) override {
    if (!ok) {  // the client half-closed: the trace is complete
      if (command_id_ == 0) {
        Finish(ToGrpcStatus(absl::InvalidArgumentError("stream carried no chunk with a command_id")));
        return;
      }
      service_->Submit(command_id_, rig_id_, samples_, lease_next_, response_,
                       [this](absl::Status status) { Finish(ToGrpcStatus(status)); });
      return;
    }
    if (command_id_ == 0) {
      command_id_ = chunk_.command_id();
      rig_id_ = chunk_.rig_id();
      lease_next_ = chunk_.lease_next();
    } else if (chunk_.command_id() != 0 && chunk_.command_id() != command_id_) {
      Finish(ToGrpcStatus(absl::InvalidArgumentError(
          absl::StrCat("chunk for command ", chunk_.command_id(), " in a stream for command ", command_id_))));
      return;
    }
    AppendSamples(chunk_.samples(), &samples_);
    if (samples_.t_size() > s_.config->max_trace_samples) {
      Finish(ToGrpcStatus(absl::ResourceExhaustedError(
          absl::StrCat("streamed trace exceeds ", s_.config->max_trace_samples, " samples"))));
      return;
    }
    StartRead(&chunk_);
  }

  void OnDone() override { delete this; }

 private:
  ProbeServiceImpl* service_;
  const ServiceContext s_;
  pb::SubmitTraceResponse* response_;
  pb::SubmitTraceChunk chunk_;
  int64_t command_id_ = 0;
  std::string rig_id_;
  bool lease_next_ = false;
  pb::TraceSamples samples_;
};

}  // namespace

grpc::ServerUnaryReactor* ProbeServiceImpl::LeaseCommand(grpc::CallbackServerContext* context,
                                                         const pb::LeaseCommandRequest* request,
                                                         pb::LeaseCommandResponse* response) {
  grpc::ServerUnaryReactor* reactor = context->DefaultReactor();
  absl::Status admitted = s_.gate->Admit(*context, Role::kProbe, "LeaseCommand");
  if (admitted.ok()) admitted = ValidateRigId(request->rig_id());
  if (admitted.ok() && request->job_id() < 0) admitted = absl::InvalidArgumentError("job_id must be >= 0 (0 = any)");
  if (!admitted.ok()) {
    FinishUnary(reactor, "LeaseCommand", admitted);
    return reactor;
  }
  const std::string rig_id = request->rig_id();
  s_.coordinator->LeaseCommand(rig_id, request->job_id(), [reactor, response, rig_id](absl::StatusOr<LeaseOutcome> outcome) {
    if (!outcome.ok()) {
      FinishUnary(reactor, "LeaseCommand", outcome.status());
      return;
    }
    FillLeaseResponse(*outcome, response);
    if (outcome->record) {
      spdlog::debug("rpc=LeaseCommand rig={} command_id={} job_id={} vertex={} attempt={}", rig_id, outcome->record->id,
                    outcome->record->job_id, outcome->record->site_vertex, outcome->record->attempt);
    }
    FinishUnary(reactor, "LeaseCommand", absl::OkStatus());
  });
  return reactor;
}

void ProbeServiceImpl::Submit(int64_t command_id, const std::string& rig_id, const pb::TraceSamples& samples,
                              bool lease_next, pb::SubmitTraceResponse* response,
                              std::function<void(absl::Status)> finish) {
  if (command_id <= 0) {
    finish(absl::InvalidArgumentError("command_id must be a positive command id"));
    return;
  }
  if (absl::Status s = ValidateRigId(rig_id); !s.ok()) {
    finish(s);
    return;
  }
  absl::StatusOr<DragTrace> trace = DragTraceFromProto(samples, s_.config->max_trace_samples);
  if (!trace.ok()) {
    finish(absl::Status(trace.status().code(), absl::StrCat("command ", command_id, ": ", trace.status().message())));
    return;
  }
  s_.coordinator->SubmitTrace(
      command_id, rig_id, std::move(*trace), lease_next,
      [response, rig_id, finish = std::move(finish)](absl::StatusOr<SubmitOutcome> outcome) {
        if (!outcome.ok()) {
          finish(outcome.status());
          return;
        }
        TraceRecord trace_record;
        trace_record.id = outcome->trace_id;
        trace_record.command_id = outcome->command.id;
        trace_record.job_id = outcome->command.job_id;
        // The trace and its first fit are stored at one time (also right for
        // a retry's reply, which gets the original acceptance time).
        trace_record.received_unix_ms = outcome->fit.created_unix_ms;
        absl::StatusOr<pb::Sample> sample =
            BuildSample(trace_record, outcome->command, outcome->fit, &outcome->probe, outcome->decoded_fit.get());
        if (!sample.ok()) {  // the trace is stored; a retry reads it back the same way
          finish(sample.status());
          return;
        }
        *response->mutable_sample() = std::move(*sample);
        response->set_already_accepted(outcome->already_accepted);
        *response->mutable_progress() = ProgressToProto(outcome->progress);
        if (outcome->next) FillLeaseResponse(*outcome->next, response->mutable_next());
        spdlog::debug("rpc=SubmitTrace rig={} command_id={} trace_id={} mu={:.4f} retry={}", rig_id,
                      outcome->command.id, outcome->trace_id, response->sample().fit().friction().mu(),
                      outcome->already_accepted);
        finish(absl::OkStatus());
      });
}

grpc::ServerUnaryReactor* ProbeServiceImpl::SubmitTrace(grpc::CallbackServerContext* context,
                                                        const pb::SubmitTraceRequest* request,
                                                        pb::SubmitTraceResponse* response) {
  grpc::ServerUnaryReactor* reactor = context->DefaultReactor();
  absl::Status admitted = s_.gate->Admit(*context, Role::kProbe, "SubmitTrace");
  if (!admitted.ok()) {
    FinishUnary(reactor, "SubmitTrace", admitted);
    return reactor;
  }
  Submit(request->command_id(), request->rig_id(), request->samples(), request->lease_next(), response,
         [reactor](absl::Status status) { FinishUnary(reactor, "SubmitTrace", status); });
  return reactor;
}

grpc::ServerReadReactor<pb::SubmitTraceChunk>* ProbeServiceImpl::SubmitTraceStream(grpc::CallbackServerContext* context,
                                                                                   pb::SubmitTraceResponse* response) {
  auto* reactor = new SubmitStreamReactor(this, s_, response);
  absl::Status admitted = s_.gate->Admit(*context, Role::kProbe, "SubmitTraceStream");
  if (!admitted.ok()) {
    reactor->Finish(ToGrpcStatus(admitted));
    return reactor;
  }
  reactor->Start();
  return reactor;
}

grpc::ServerUnaryReactor* ProbeServiceImpl::ReportFailure(grpc::CallbackServerContext* context,
                                                          const pb::ReportFailureRequest* request,
                                                          pb::ReportFailureResponse* response) {
  grpc::ServerUnaryReactor* reactor = context->DefaultReactor();
  absl::Status admitted = s_.gate->Admit(*context, Role::kProbe, "ReportFailure");
  if (admitted.ok()) admitted = ValidateRigId(request->rig_id());
  if (!admitted.ok()) {
    FinishUnary(reactor, "ReportFailure", admitted);
    return reactor;
  }
  s_.coordinator->ReportFailure(request->command_id(), request->rig_id(), request->reason(),
                                [reactor, response](absl::StatusOr<bool> will_retry) {
                                  if (will_retry.ok()) response->set_will_retry(*will_retry);
                                  FinishUnary(reactor, "ReportFailure", will_retry.status());
                                });
  return reactor;
}

}  // namespace surfmap
