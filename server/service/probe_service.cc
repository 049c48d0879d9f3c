#include "absl/strings/str_cat.h"
#include "server/base/log_text.h"
#include "server/base/utf8_text.h"
#include "server/service/grpc_services.h"
#include "server/service/proto_builders.h"
#include "server/service/proto_conversion.h"
#include "server/service/provenance_proto.h"
#include "server/service/rig_registration_proto.h"

namespace surfmap {
namespace {

absl::Status ValidateRigId(const std::string& rig_id) { return ValidateName("rig_id", rig_id, 1, 100); }

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
    if (outcome.rig_frame && outcome.rig_registration) {
      const RigFrameCommand& rf = *outcome.rig_frame;
      const RegisteredRig& rig = *outcome.rig_registration;
      pb::RigFrameCommand* frame = out->mutable_rig_frame();
      frame->set_registration_id(rig.record.id);
      frame->set_registration_version(rig.record.version);
      *frame->mutable_position() = ToProto(rf.position);
      *frame->mutable_normal() = ToProto(rf.normal);
      *frame->mutable_drag_direction() = ToProto(rf.drag_direction);
      *frame->mutable_start() = ToProto(rf.start);
      *frame->mutable_end() = ToProto(rf.end);
      for (const Eigen::Vector3d& p : rf.tool_centre_path) *frame->add_tool_centre_path() = ToProto(p);
      frame->set_tip_radius_mm(rig.registration.tip_radius_mm);
      *frame->mutable_sensor_rotation() = QuaternionToProto(rig.registration.sensor_rotation);
    }
  } else if (!outcome.job_finished) {
    *response->mutable_retry_after() = DurationFromMs(outcome.retry_after_ms);
  }
}

// RESOURCE_EXHAUSTED naming the column when `more` would take any column of
// `held` past `max_samples` values.
absl::Status CheckStreamColumns(const pb::TraceSamples& more, const pb::TraceSamples& held, int max_samples) {
  const struct {
    const char* name;
    int held, more;
  } columns[] = {{"t", held.t_size(), more.t_size()},       {"x", held.x_size(), more.x_size()},
                 {"y", held.y_size(), more.y_size()},       {"z", held.z_size(), more.z_size()},
                 {"fx", held.fx_size(), more.fx_size()},    {"fy", held.fy_size(), more.fy_size()},
                 {"fz", held.fz_size(), more.fz_size()},    {"phases", held.phases_size(), more.phases_size()}};
  for (const auto& c : columns) {
    const int64_t total = static_cast<int64_t>(c.held) + c.more;
    if (total > max_samples) {
      return absl::ResourceExhaustedError(absl::StrCat("streamed trace: column ", c.name, " would hold ", total,
                                                       " values; the limit is ", max_samples,
                                                       " samples per trace (max_trace_samples)"));
    }
  }
  return absl::OkStatus();
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
      service_->Submit(command_id_, rig_id_, &samples_, lease_next_, frame_, registration_id_, provenance_, response_,
                       [this](absl::Status status) { Finish(ToGrpcStatus(status)); });
      return;
    }
    if (command_id_ == 0) {
      command_id_ = chunk_.command_id();
      rig_id_ = chunk_.rig_id();
      lease_next_ = chunk_.lease_next();
      provenance_ = chunk_.provenance();
      frame_ = chunk_.frame();
      registration_id_ = chunk_.registration_id();
    } else if (chunk_.command_id() != 0 && chunk_.command_id() != command_id_) {
      Finish(ToGrpcStatus(absl::InvalidArgumentError(
          absl::StrCat("chunk for command ", chunk_.command_id(), " in a stream for command ", command_id_))));
      return;
    }
    // Every column is counted, before it is appended: a stream of chunks with
    // an empty `t` and millions of `x` must be refused at the first chunk
    // that passes the limit, not after it has been held in memory.
    if (absl::Status bounded = CheckStreamColumns(chunk_.samples(), samples_, s_.config->max_trace_samples);
        !bounded.ok()) {
      Finish(ToGrpcStatus(bounded));
      return;
    }
    AppendSamples(chunk_.samples(), &samples_);
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
  pb::Provenance provenance_;
  pb::TraceFrame frame_ = pb::TRACE_FRAME_UNSPECIFIED;
  int64_t registration_id_ = 0;
  pb::TraceSamples samples_;  // lives until OnDone, after the submission finished
};

}  // namespace

grpc::ServerUnaryReactor* ProbeServiceImpl::LeaseCommand(grpc::CallbackServerContext* context,
                                                         const pb::LeaseCommandRequest* request,
                                                         pb::LeaseCommandResponse* response) {
  return HandleUnaryAsync(context, s_, Role::kProbe, "LeaseCommand", [this, request, response](FinishFn finish) {
    const std::string rig_id = request->rig_id();
    s_.coordinator->probes().LeaseCommand(
        rig_id, request->job_id(), [response, rig_id, finish = std::move(finish)](absl::StatusOr<LeaseOutcome> outcome) {
          if (!outcome.ok()) return finish(outcome.status());
          FillLeaseResponse(*outcome, response);
          if (outcome->record) {
            spdlog::debug("command leased rpc=LeaseCommand rig={} command_id={} job_id={} vertex={} attempt={}", LogQuote(rig_id),
                          outcome->record->id, outcome->record->job_id, outcome->record->site_vertex,
                          outcome->record->attempt);
          }
          finish(absl::OkStatus());
        });
  });
}

void ProbeServiceImpl::Submit(int64_t command_id, const std::string& rig_id, const pb::TraceSamples* samples,
                              bool lease_next, pb::TraceFrame frame, int64_t registration_id,
                              const pb::Provenance& provenance_proto, pb::SubmitTraceResponse* response,
                              FinishFn finish) {
  if (command_id <= 0) return finish(absl::InvalidArgumentError("command_id must be a positive command id"));
  if (absl::Status s = ValidateRigId(rig_id); !s.ok()) return finish(s);
  absl::StatusOr<Provenance> provenance = ProvenanceFromProto(provenance_proto);
  if (!provenance.ok()) return finish(provenance.status());
  std::string metadata_json = MetadataJsonOf(*provenance);
  ProbeProtocol::TraceFrameChoice choice;
  absl::StatusOr<TraceFrame> parsed_frame = TraceFrameFromProto(frame);
  if (!parsed_frame.ok()) return finish(parsed_frame.status());
  choice.frame = *parsed_frame;
  if (registration_id < 0) return finish(absl::InvalidArgumentError("registration_id must be >= 0 (0 = the latest)"));
  choice.registration_id = registration_id;
  const int max_samples = s_.config->max_trace_samples;
  // The conversion is O(samples): it runs on the pool with the fit. `samples`
  // lives until the call finishes.
  auto source = [samples, max_samples, command_id]() -> absl::StatusOr<DragTrace> {
    absl::StatusOr<DragTrace> trace = DragTraceFromProto(*samples, max_samples);
    if (!trace.ok()) {
      return absl::Status(trace.status().code(), absl::StrCat("command ", command_id, ": ", trace.status().message()));
    }
    return trace;
  };
  s_.coordinator->probes().SubmitTrace(
      command_id, rig_id, source, lease_next, choice,
      [response, rig_id, command_id, finish = std::move(finish)](absl::StatusOr<SubmitOutcome> outcome) {
        if (!outcome.ok()) {
          // Every refusal, whatever its cause (an implausible trace, an expired
          // lease, a conflict): a rig whose traces keep being refused is what an
          // operator looks for.
          spdlog::info("trace rejected rig={} command_id={} code={} reason={}", LogQuote(rig_id), command_id,
                       absl::StatusCodeToString(outcome.status().code()), LogQuote(std::string(outcome.status().message())));
          return finish(outcome.status());
        }
        // A retry answers with what the first submission stored, its provenance included.
        absl::StatusOr<pb::Sample> sample = BuildSample(*outcome, &outcome->probe, outcome->decoded_fit.get());
        if (!sample.ok()) return finish(sample.status());  // stored; a retry reads it back the same way
        *response->mutable_sample() = std::move(*sample);
        response->set_already_accepted(outcome->already_accepted);
        *response->mutable_progress() = ProgressToProto(outcome->progress);
        if (outcome->next) FillLeaseResponse(*outcome->next, response->mutable_next());
        spdlog::debug("trace accepted rpc=SubmitTrace rig={} command_id={} trace_id={} mu={:.4f} retry={}", LogQuote(rig_id),
                      outcome->command.id, outcome->trace_id, response->sample().fit().friction().mu(),
                      outcome->already_accepted);
        finish(absl::OkStatus());
      },
      metadata_json);
}

grpc::ServerUnaryReactor* ProbeServiceImpl::SubmitTrace(grpc::CallbackServerContext* context,
                                                        const pb::SubmitTraceRequest* request,
                                                        pb::SubmitTraceResponse* response) {
  return HandleUnaryAsync(context, s_, Role::kProbe, "SubmitTrace", [this, request, response](FinishFn finish) {
    Submit(request->command_id(), request->rig_id(), &request->samples(), request->lease_next(), request->frame(),
           request->registration_id(), request->provenance(), response, std::move(finish));
  });
}

grpc::ServerReadReactor<pb::SubmitTraceChunk>* ProbeServiceImpl::SubmitTraceStream(grpc::CallbackServerContext* context,
                                                                                   pb::SubmitTraceResponse* response) {
  auto* reactor = new SubmitStreamReactor(this, s_, response);
  absl::Status admitted = AdmitCall(*context, s_, Role::kProbe, "SubmitTraceStream");
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
  return HandleUnaryAsync(context, s_, Role::kProbe, "ReportFailure", [this, request, response](FinishFn finish) {
    FailureKind kind;
    switch (request->kind()) {
      case pb::FAILURE_KIND_UNSPECIFIED:  // rigs from before kinds existed
      case pb::FAILURE_KIND_TRANSIENT: kind = FailureKind::kTransient; break;
      case pb::FAILURE_KIND_UNREACHABLE: kind = FailureKind::kUnreachable; break;
      default: return finish(absl::InvalidArgumentError(absl::StrCat("kind: unknown value ", request->kind())));
    }
    const int64_t command_id = request->command_id();
    const std::string rig_id = request->rig_id();
    const std::string reason = request->reason();
    s_.coordinator->probes().ReportFailure(
        command_id, rig_id, reason, kind,
        [response, command_id, rig_id, reason, kind, finish = std::move(finish)](absl::StatusOr<bool> will_retry) {
          if (will_retry.ok()) {
            response->set_will_retry(*will_retry);
            spdlog::info("rig failure reported rig={} command_id={} kind={} will_retry={} reason={}", LogQuote(rig_id),
                         command_id, kind == FailureKind::kUnreachable ? "unreachable" : "transient", *will_retry,
                         LogQuote(reason));
          }
          finish(will_retry.status());
        });
  });
}

}  // namespace surfmap
