// The gRPC services of surfmap.v1 (callback API). Each handler validates its
// request, admits the caller through the RequestGate, and delegates to the
// JobCoordinator; proto types end here.
#pragma once

#include "proto/surfmap/v1/surfmap.grpc.pb.h"
#include "server/service/service_context.h"

namespace surfmap {

namespace pb = ::surfmap::v1;

class ObjectServiceImpl final : public pb::ObjectService::CallbackService {
 public:
  explicit ObjectServiceImpl(ServiceContext services) : s_(services) {}
  grpc::ServerUnaryReactor* UploadObject(grpc::CallbackServerContext*, const pb::UploadObjectRequest*,
                                         pb::UploadObjectResponse*) override;
  grpc::ServerUnaryReactor* GetObject(grpc::CallbackServerContext*, const pb::GetObjectRequest*,
                                      pb::GetObjectResponse*) override;
  grpc::ServerUnaryReactor* ListObjects(grpc::CallbackServerContext*, const pb::ListObjectsRequest*,
                                        pb::ListObjectsResponse*) override;
  grpc::ServerUnaryReactor* GetMesh(grpc::CallbackServerContext*, const pb::GetMeshRequest*,
                                    pb::GetMeshResponse*) override;
  // Frames and calibration (rig_registration_service.cc).
  grpc::ServerUnaryReactor* SetRigRegistration(grpc::CallbackServerContext*, const pb::SetRigRegistrationRequest*,
                                               pb::SetRigRegistrationResponse*) override;
  grpc::ServerUnaryReactor* GetRigRegistration(grpc::CallbackServerContext*, const pb::GetRigRegistrationRequest*,
                                               pb::GetRigRegistrationResponse*) override;
  grpc::ServerUnaryReactor* ListRigRegistrations(grpc::CallbackServerContext*,
                                                 const pb::ListRigRegistrationsRequest*,
                                                 pb::ListRigRegistrationsResponse*) override;

 private:
  ServiceContext s_;
};

class JobServiceImpl final : public pb::JobService::CallbackService {
 public:
  explicit JobServiceImpl(ServiceContext services) : s_(services) {}
  grpc::ServerUnaryReactor* CreateJob(grpc::CallbackServerContext*, const pb::CreateJobRequest*,
                                      pb::CreateJobResponse*) override;
  grpc::ServerUnaryReactor* GetJob(grpc::CallbackServerContext*, const pb::GetJobRequest*,
                                   pb::GetJobResponse*) override;
  grpc::ServerUnaryReactor* ListJobs(grpc::CallbackServerContext*, const pb::ListJobsRequest*,
                                     pb::ListJobsResponse*) override;
  grpc::ServerUnaryReactor* PauseJob(grpc::CallbackServerContext*, const pb::SetJobStateRequest*,
                                     pb::SetJobStateResponse*) override;
  grpc::ServerUnaryReactor* ResumeJob(grpc::CallbackServerContext*, const pb::SetJobStateRequest*,
                                      pb::SetJobStateResponse*) override;
  grpc::ServerUnaryReactor* CancelJob(grpc::CallbackServerContext*, const pb::SetJobStateRequest*,
                                      pb::SetJobStateResponse*) override;
  grpc::ServerUnaryReactor* GetPlan(grpc::CallbackServerContext*, const pb::GetPlanRequest*,
                                    pb::GetPlanResponse*) override;
  grpc::ServerUnaryReactor* ListJobEvents(grpc::CallbackServerContext*, const pb::ListJobEventsRequest*,
                                          pb::ListJobEventsResponse*) override;
  grpc::ServerWriteReactor<pb::JobUpdate>* WatchJob(grpc::CallbackServerContext*,
                                                    const pb::WatchJobRequest*) override;

 private:
  grpc::ServerUnaryReactor* ChangeState(grpc::CallbackServerContext*, const pb::SetJobStateRequest*,
                                        pb::SetJobStateResponse*, JobState target, const char* method);
  ServiceContext s_;
};

class ProbeServiceImpl final : public pb::ProbeService::CallbackService {
 public:
  explicit ProbeServiceImpl(ServiceContext services) : s_(services) {}
  grpc::ServerUnaryReactor* LeaseCommand(grpc::CallbackServerContext*, const pb::LeaseCommandRequest*,
                                         pb::LeaseCommandResponse*) override;
  grpc::ServerUnaryReactor* SubmitTrace(grpc::CallbackServerContext*, const pb::SubmitTraceRequest*,
                                        pb::SubmitTraceResponse*) override;
  grpc::ServerReadReactor<pb::SubmitTraceChunk>* SubmitTraceStream(grpc::CallbackServerContext*,
                                                                   pb::SubmitTraceResponse*) override;
  grpc::ServerUnaryReactor* ReportFailure(grpc::CallbackServerContext*, const pb::ReportFailureRequest*,
                                          pb::ReportFailureResponse*) override;

  // Shared by the unary and streamed submissions: validates, fits, stores,
  // then calls `finish` once the trace is durable (or was refused).
  // `samples` must live until `finish` was called.
  // `provenance` lives until the call finishes, like `samples`.
  void Submit(int64_t command_id, const std::string& rig_id, const pb::TraceSamples* samples, bool lease_next,
              pb::TraceFrame frame, int64_t registration_id, const pb::Provenance& provenance,
              pb::SubmitTraceResponse* response, FinishFn finish);

 private:
  ServiceContext s_;
};

class MapServiceImpl final : public pb::MapService::CallbackService {
 public:
  explicit MapServiceImpl(ServiceContext services) : s_(services) {}
  grpc::ServerUnaryReactor* GetSample(grpc::CallbackServerContext*, const pb::GetSampleRequest*,
                                      pb::GetSampleResponse*) override;
  grpc::ServerUnaryReactor* ListSamples(grpc::CallbackServerContext*, const pb::ListSamplesRequest*,
                                        pb::ListSamplesResponse*) override;
  grpc::ServerUnaryReactor* GetMap(grpc::CallbackServerContext*, const pb::GetMapRequest*,
                                   pb::GetMapResponse*) override;
  grpc::ServerUnaryReactor* QueryMap(grpc::CallbackServerContext*, const pb::QueryMapRequest*,
                                     pb::QueryMapResponse*) override;
  grpc::ServerUnaryReactor* SimulateDrag(grpc::CallbackServerContext*, const pb::SimulateDragRequest*,
                                         pb::SimulateDragResponse*) override;

 private:
  ServiceContext s_;
};

class TraceServiceImpl final : public pb::TraceService::CallbackService {
 public:
  explicit TraceServiceImpl(ServiceContext services) : s_(services) {}
  grpc::ServerUnaryReactor* GetTrace(grpc::CallbackServerContext*, const pb::GetTraceRequest*,
                                     pb::GetTraceResponse*) override;
  grpc::ServerUnaryReactor* RefitJob(grpc::CallbackServerContext*, const pb::RefitJobRequest*,
                                     pb::RefitJobResponse*) override;
  grpc::ServerUnaryReactor* ListRejectedTraces(grpc::CallbackServerContext*, const pb::ListRejectedTracesRequest*,
                                               pb::ListRejectedTracesResponse*) override;
  grpc::ServerUnaryReactor* GetRejectedTrace(grpc::CallbackServerContext*, const pb::GetRejectedTraceRequest*,
                                             pb::GetRejectedTraceResponse*) override;
  // import and provenance (issue 13): trace_import_handler.cc
  grpc::ServerUnaryReactor* ImportTrace(grpc::CallbackServerContext*, const pb::ImportTraceRequest*,
                                        pb::ImportTraceResponse*) override;

 private:
  ServiceContext s_;
};

}  // namespace surfmap
