// ProbeEndpoint: the rig's view of the server's ProbeService, one method per
// RPC. GrpcProbeEndpoint talks to surfmapd; tests substitute a scripted fake
// (the generated stub interface drags in the whole async API).
#pragma once

#include <memory>

#include <grpcpp/grpcpp.h>
#include "clients/cli/remote_call.h"
#include "proto/surfmap/v1/surfmap.grpc.pb.h"

namespace surfmap::rig {

class ProbeEndpoint {
 public:
  virtual ~ProbeEndpoint() = default;
  virtual grpc::Status LeaseCommand(const surfmap::v1::LeaseCommandRequest& request,
                                    surfmap::v1::LeaseCommandResponse* response) = 0;
  virtual grpc::Status SubmitTrace(const surfmap::v1::SubmitTraceRequest& request,
                                   surfmap::v1::SubmitTraceResponse* response) = 0;
  virtual grpc::Status ReportFailure(const surfmap::v1::ReportFailureRequest& request,
                                     surfmap::v1::ReportFailureResponse* response) = 0;
};

// Each call gets the options' deadline and bearer token.
class GrpcProbeEndpoint : public ProbeEndpoint {
 public:
  explicit GrpcProbeEndpoint(const cli::RemoteOptions& options)
      : options_(options), stub_(surfmap::v1::ProbeService::NewStub(cli::ConnectChannel(options))) {}

  grpc::Status LeaseCommand(const surfmap::v1::LeaseCommandRequest& request,
                            surfmap::v1::LeaseCommandResponse* response) override;
  grpc::Status SubmitTrace(const surfmap::v1::SubmitTraceRequest& request,
                           surfmap::v1::SubmitTraceResponse* response) override;
  grpc::Status ReportFailure(const surfmap::v1::ReportFailureRequest& request,
                             surfmap::v1::ReportFailureResponse* response) override;

 private:
  cli::RemoteOptions options_;
  std::unique_ptr<surfmap::v1::ProbeService::Stub> stub_;
};

}  // namespace surfmap::rig
