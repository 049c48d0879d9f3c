// ProbeEndpoint: the rig's view of the server's ProbeService, one method per
// RPC. GrpcProbeEndpoint talks to surfmapd; tests substitute a scripted fake
// (the generated stub interface drags in the whole async API).
#pragma once

#include <grpcpp/grpcpp.h>

#include <memory>

#include "clients/remote/remote_call.h"
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
//
// After a call failed UNAVAILABLE the next call goes over a fresh channel
// (with its own subchannel): gRPC 1.51's channel stays in TRANSIENT_FAILURE
// for seconds after the server is back (its subchannel's backoff ends in
// IDLE and nothing asks it to reconnect until the next name re-resolution),
// while a rig waiting out a server restart should be back as soon as the
// server listens again.
class GrpcProbeEndpoint : public ProbeEndpoint {
 public:
  explicit GrpcProbeEndpoint(const cli::RemoteOptions& options);

  grpc::Status LeaseCommand(const surfmap::v1::LeaseCommandRequest& request,
                            surfmap::v1::LeaseCommandResponse* response) override;
  grpc::Status SubmitTrace(const surfmap::v1::SubmitTraceRequest& request,
                           surfmap::v1::SubmitTraceResponse* response) override;
  grpc::Status ReportFailure(const surfmap::v1::ReportFailureRequest& request,
                             surfmap::v1::ReportFailureResponse* response) override;

 private:
  surfmap::v1::ProbeService::Stub& Stub();
  grpc::Status Noted(grpc::Status status);

  cli::RemoteOptions options_;
  std::unique_ptr<surfmap::v1::ProbeService::Stub> stub_;
  bool reconnect_ = false;
};

}  // namespace surfmap::rig
