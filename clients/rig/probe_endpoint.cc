#include "clients/rig/probe_endpoint.h"

namespace surfmap::rig {

namespace pb = ::surfmap::v1;

namespace {

// No wait for the connection: the next call connects at once, and if the
// server is still down it fails fast and the rig loop's backoff decides when
// to try again.
std::shared_ptr<grpc::Channel> FreshChannel(const cli::RemoteOptions& options) {
  return cli::MakeChannel(options, /*own_subchannel=*/true);
}

}  // namespace

GrpcProbeEndpoint::GrpcProbeEndpoint(const cli::RemoteOptions& options)
    : options_(options), stub_(pb::ProbeService::NewStub(cli::ConnectChannel(options))) {}

pb::ProbeService::Stub& GrpcProbeEndpoint::Stub() {
  if (reconnect_) {
    stub_ = pb::ProbeService::NewStub(FreshChannel(options_));
    reconnect_ = false;
  }
  return *stub_;
}

grpc::Status GrpcProbeEndpoint::Noted(grpc::Status status) {
  if (status.error_code() == grpc::StatusCode::UNAVAILABLE) reconnect_ = true;
  return status;
}

grpc::Status GrpcProbeEndpoint::LeaseCommand(const pb::LeaseCommandRequest& request,
                                             pb::LeaseCommandResponse* response) {
  grpc::ClientContext context;
  cli::PrepareContext(options_, &context);
  return Noted(Stub().LeaseCommand(&context, request, response));
}

grpc::Status GrpcProbeEndpoint::SubmitTrace(const pb::SubmitTraceRequest& request,
                                            pb::SubmitTraceResponse* response) {
  grpc::ClientContext context;
  cli::PrepareContext(options_, &context);
  return Noted(Stub().SubmitTrace(&context, request, response));
}

grpc::Status GrpcProbeEndpoint::ReportFailure(const pb::ReportFailureRequest& request,
                                              pb::ReportFailureResponse* response) {
  grpc::ClientContext context;
  cli::PrepareContext(options_, &context);
  return Noted(Stub().ReportFailure(&context, request, response));
}

}  // namespace surfmap::rig
