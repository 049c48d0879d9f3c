// TraceService.ImportTrace (issue 13): a drag recorded elsewhere into a job's
// map. The handler only validates the request and hands the file's bytes to
// the importer (server/jobs/trace_import.h), which hashes, reads, locates,
// checks, fits and stores it on the probe pool; the answer comes once durable.
#include <memory>

#include "absl/strings/str_cat.h"
#include "server/base/log_text.h"
#include "server/service/grpc_services.h"
#include "server/service/proto_builders.h"
#include "server/service/provenance_proto.h"

namespace surfmap {

grpc::ServerUnaryReactor* TraceServiceImpl::ImportTrace(grpc::CallbackServerContext* context,
                                                        const pb::ImportTraceRequest* request,
                                                        pb::ImportTraceResponse* response) {
  // Importing adds data to a job as a rig does: the probe role (steer includes it).
  return HandleUnaryAsync(context, s_, Role::kProbe, "ImportTrace", [this, request, response](FinishFn finish) {
    absl::StatusOr<Provenance> provenance = ProvenanceFromProto(request->provenance());
    if (!provenance.ok()) return finish(provenance.status());
    absl::StatusOr<int64_t> recorded = UnixMsFromProto(request->recorded(), request->has_recorded(), "recorded");
    if (!recorded.ok()) return finish(recorded.status());
    TraceImportRequest import;
    import.job_id = request->job_id();
    import.source = request->source();
    import.file_name = request->file_name();
    import.recorded_unix_ms = *recorded;
    import.provenance = std::move(*provenance);
    // The request lives until the call finishes; the pool task holds its bytes by pointer.
    auto csv = std::shared_ptr<const std::string>(&request->csv(), [](const std::string*) {});
    const int64_t job_id = import.job_id;
    const std::string source = import.source;
    s_.coordinator->imports().Import(
        std::move(import), std::move(csv), s_.config->max_trace_samples,
        [response, job_id, source, finish = std::move(finish)](absl::StatusOr<TraceImportOutcome> outcome) {
          if (!outcome.ok()) {
            spdlog::info("import refused job_id={} source={} code={} reason={}", job_id, LogQuote(source),
                         absl::StatusCodeToString(outcome.status().code()),
                         LogQuote(std::string(outcome.status().message())));
            return finish(outcome.status());
          }
          absl::StatusOr<pb::Sample> sample = BuildSample(*outcome, &outcome->probe, outcome->decoded_fit.get());
          if (!sample.ok()) return finish(sample.status());  // stored; a repeat reads it back the same way
          *response->mutable_sample() = std::move(*sample);
          response->set_already_imported(outcome->already_imported);
          finish(absl::OkStatus());
        });
  });
}

}  // namespace surfmap
