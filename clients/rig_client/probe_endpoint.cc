#include "clients/rig_client/probe_endpoint.h"

namespace surfmap::rig {

namespace pb = ::surfmap::v1;

grpc::Status GrpcProbeEndpoint::LeaseCommand(const pb::LeaseCommandRequest& request,
                                             pb::LeaseCommandResponse* response) {
  grpc::ClientContext context;
  cli::PrepareContext(options_, &context);
  return stub_->LeaseCommand(&context, request, response);
}

grpc::Status GrpcProbeEndpoint::SubmitTrace(const pb::SubmitTraceRequest& request,
                                            pb::SubmitTraceResponse* response) {
  grpc::ClientContext context;
  cli::PrepareContext(options_, &context);
  return stub_->SubmitTrace(&context, request, response);
}

grpc::Status GrpcProbeEndpoint::ReportFailure(const pb::ReportFailureRequest& request,
                                              pb::ReportFailureResponse* response) {
  grpc::ClientContext context;
  cli::PrepareContext(options_, &context);
  return stub_->ReportFailure(&context, request, response);
}

}  // namespace surfmap::rig
