#include <algorithm>
#include <atomic>

#include "absl/strings/str_cat.h"
#include "absl/strings/ascii.h"
#include "server/service/provenance_proto.h"
#include "server/service/grpc_services.h"
#include "server/service/proto_builders.h"
#include "server/service/job_watch_reactor.h"
#include "server/service/proto_conversion.h"
#include "server/jobs/plan_estimate.h"

namespace surfmap {
namespace {

pb::SiteState SiteStateToProto(SiteState s) {
  switch (s) {
    case SiteState::kPending: return pb::SITE_STATE_PENDING;
    case SiteState::kIssued: return pb::SITE_STATE_ISSUED;
    case SiteState::kMeasured: return pb::SITE_STATE_MEASURED;
    case SiteState::kFailed: return pb::SITE_STATE_FAILED;
    case SiteState::kSkipped: return pb::SITE_STATE_SKIPPED;
  }
  return pb::SITE_STATE_UNSPECIFIED;
}

}  // namespace

grpc::ServerUnaryReactor* JobServiceImpl::CreateJob(grpc::CallbackServerContext* context,
                                                    const pb::CreateJobRequest* request,
                                                    pb::CreateJobResponse* response) {
  // Refining the object to the job's finest level can take a while: on the pool.
  return HandleUnaryOnPool(context, s_, Role::kSteer, "CreateJob", [this, request, response]() -> absl::Status {
    if (!request->has_spec()) return absl::InvalidArgumentError("spec is missing");
    absl::StatusOr<JobParams> params =
        JobParamsFromProto(request->spec(), static_cast<int64_t>(s_.config->default_lease_s * 1000));
    if (!params.ok()) return params.status();
    absl::StatusOr<Provenance> provenance = ProvenanceFromProto(request->provenance());
    if (!provenance.ok()) return provenance.status();
    // The levels and the surface the job will plan on (cached: CreateJob
    // reuses them), so the estimate can refuse a job before anything is stored.
    if (params->finest_level == kAutoLevel || params->map_level == kAutoLevel) {
      absl::StatusOr<std::shared_ptr<const LoopSurface>> control =
          s_.coordinator->Surface(params->object_id, 0, params->site_spacing_mm);
      if (!control.ok()) return control.status();
      ResolveAutoLevels((*control)->level(0), *params);
    }
    if (std::string why; !params->IsValid(&why)) return absl::InvalidArgumentError("job: " + why);
    absl::StatusOr<std::shared_ptr<const LoopSurface>> surface =
        s_.coordinator->Surface(params->object_id, params->map_level, params->site_spacing_mm);
    if (!surface.ok()) return surface.status();
    absl::StatusOr<PlanEstimate> estimate = EstimatePlan(*params, **surface);
    if (!estimate.ok()) return estimate.status();
    absl::StatusOr<ObjectRecord> object = s_.coordinator->reads().GetObject(params->object_id);
    if (!object.ok()) return object.status();
    absl::StatusOr<JobSnapshot> job = s_.coordinator->CreateJob(*params, MetadataJsonOf(*provenance));
    if (!job.ok()) return job.status();
    *response->mutable_job() = JobInfoToProto(*job);
    *response->mutable_estimate() =
        PlanEstimateToProto(*estimate, estimate->control_vertices < object->control_vertices);
    for (const std::string& w : estimate->warnings) response->add_warnings(w);
    spdlog::info("rpc=CreateJob job_id={} level0_sites={} expected_sites={} expected_robot_s={:.0f} warnings={}",
                 job->record.id, estimate->level0_sites, estimate->expected_sites, estimate->expected_seconds,
                 estimate->warnings.size());
    spdlog::info("job created rpc=CreateJob job_id={} object_id={} mode={} levels={}..{} initial_sites={}", job->record.id,
                 params->object_id, std::string(PlanModeName(params->mode)), params->coarsest_level, params->finest_level,
                 job->progress.pending + job->progress.issued);
    return absl::OkStatus();
  });
}

grpc::ServerUnaryReactor* JobServiceImpl::GetJob(grpc::CallbackServerContext* context, const pb::GetJobRequest* request,
                                                 pb::GetJobResponse* response) {
  // A job in memory is answered on the handler's thread (memory and one small
  // read); a finished job not in memory is loaded on the pool first.
  const bool loaded = s_.coordinator->IsJobLoaded(request->job_id());
  return HandleUnaryInlineIf(loaded, context, s_, Role::kRead, "GetJob", [this, request, response]() -> absl::Status {
    if (request->job_id() <= 0) return absl::InvalidArgumentError("job_id must be a positive job id");
    absl::StatusOr<JobSnapshot> job = s_.coordinator->GetJob(request->job_id());
    if (!job.ok()) return job.status();
    *response->mutable_job() = JobInfoToProto(*job);
    return absl::OkStatus();
  });
}

grpc::ServerUnaryReactor* JobServiceImpl::ListJobs(grpc::CallbackServerContext* context,
                                                   const pb::ListJobsRequest* request, pb::ListJobsResponse* response) {
  // May load finished jobs that are not in memory: on the pool.
  return HandleUnaryOnPool(context, s_, Role::kRead, "ListJobs", [this, request, response]() -> absl::Status {
    if (request->object_id() < 0) return absl::InvalidArgumentError("object_id must be >= 0 (0 = all)");
    absl::StatusOr<std::vector<JobSnapshot>> jobs = s_.coordinator->ListJobs(request->object_id());
    if (!jobs.ok()) return jobs.status();
    for (const JobSnapshot& job : *jobs) *response->add_jobs() = JobInfoToProto(job);
    return absl::OkStatus();
  });
}

grpc::ServerUnaryReactor* JobServiceImpl::ChangeState(grpc::CallbackServerContext* context,
                                                      const pb::SetJobStateRequest* request,
                                                      pb::SetJobStateResponse* response, JobState target,
                                                      const char* method) {
  // Decided at once, answered when durable: the handler's thread never waits.
  return HandleUnaryAsync(context, s_, Role::kSteer, method, [this, request, response, target, method](FinishFn finish) {
    if (request->job_id() <= 0) return finish(absl::InvalidArgumentError("job_id must be a positive job id"));
    const int64_t job_id = request->job_id();
    s_.coordinator->SetJobState(job_id, target, [response, target, method, job_id, finish = std::move(finish)](
                                                    absl::StatusOr<JobSnapshot> job) {
      if (!job.ok()) return finish(job.status());
      *response->mutable_job() = JobInfoToProto(*job);
      // "job cancelled", "job paused", "job running": one line per decision an operator made.
      spdlog::info("job {} rpc={} job_id={} state={} measured={} failed={}",
                   absl::AsciiStrToLower(std::string(JobStateName(target))), method, job_id, std::string(JobStateName(target)),
                   job->progress.measured, job->progress.failed);
      finish(absl::OkStatus());
    });
  });
}

grpc::ServerUnaryReactor* JobServiceImpl::PauseJob(grpc::CallbackServerContext* c, const pb::SetJobStateRequest* r,
                                                   pb::SetJobStateResponse* o) {
  return ChangeState(c, r, o, JobState::kPaused, "PauseJob");
}
grpc::ServerUnaryReactor* JobServiceImpl::ResumeJob(grpc::CallbackServerContext* c, const pb::SetJobStateRequest* r,
                                                    pb::SetJobStateResponse* o) {
  return ChangeState(c, r, o, JobState::kRunning, "ResumeJob");
}
grpc::ServerUnaryReactor* JobServiceImpl::CancelJob(grpc::CallbackServerContext* c, const pb::SetJobStateRequest* r,
                                                    pb::SetJobStateResponse* o) {
  return ChangeState(c, r, o, JobState::kCancelled, "CancelJob");
}

grpc::ServerUnaryReactor* JobServiceImpl::GetPlan(grpc::CallbackServerContext* context,
                                                  const pb::GetPlanRequest* request, pb::GetPlanResponse* response) {
  // A copy of the plan's sites: cheap for a job in memory (no map is built).
  const bool loaded = s_.coordinator->IsJobLoaded(request->job_id());
  return HandleUnaryInlineIf(loaded, context, s_, Role::kRead, "GetPlan", [this, request, response]() -> absl::Status {
    PlanProgress progress;
    absl::StatusOr<std::vector<SiteRecord>> sites = s_.coordinator->PlanSites(request->job_id(), &progress);
    if (!sites.ok()) return sites.status();
    // Counted after the plan's snapshot; see JobSteering::LeasedCommands.
    absl::StatusOr<LeasedCounts> leased = s_.coordinator->LeasedCommands(request->job_id(), progress);
    if (!leased.ok()) return leased.status();
    absl::StatusOr<std::shared_ptr<const LoopSurface>> surface = s_.coordinator->JobSurface(request->job_id());
    if (!surface.ok()) return surface.status();
    const SurfaceLevel& finest = (*surface)->finest();
    response->set_job_id(request->job_id());
    *response->mutable_progress() = ProgressToProto(progress, &*leased);
    for (const SiteRecord& site : *sites) {
      pb::PlanSite* out = response->add_sites();
      out->mutable_site()->set_level(site.site.level);
      out->mutable_site()->set_vertex(site.site.vertex);
      out->set_state(SiteStateToProto(site.state));
      out->set_attempts(site.failures + (site.sequence != 0 ? 1 : 0));
      out->set_failure_reason(site.reason);
      if (site.site.vertex < static_cast<int>(finest.limit_positions.size())) {
        *out->mutable_position() = ToProto(finest.limit_positions[site.site.vertex]);
      }
    }
    return absl::OkStatus();
  });
}

grpc::ServerUnaryReactor* JobServiceImpl::ListJobEvents(grpc::CallbackServerContext* context,
                                                        const pb::ListJobEventsRequest* request,
                                                        pb::ListJobEventsResponse* response) {
  return HandleUnaryOnPool(context, s_, Role::kRead, "ListJobEvents", [this, request, response]() -> absl::Status {
    if (request->job_id() <= 0) return absl::InvalidArgumentError("job_id must be a positive job id");
    if (request->after_event_id() < 0) return absl::InvalidArgumentError("after_event_id must be >= 0");
    if (request->limit() < 0 || request->limit() > 10'000) {
      return absl::InvalidArgumentError(absl::StrCat("limit must be in 0..10000 (0 = 1000), got ", request->limit()));
    }
    if (request->before_event_id() < 0) return absl::InvalidArgumentError("before_event_id must be >= 0");
    if (request->newest_first() && request->after_event_id() != 0) {
      return absl::InvalidArgumentError("newest_first pages with before_event_id; after_event_id must be 0");
    }
    if (!request->newest_first() && request->before_event_id() != 0) {
      return absl::InvalidArgumentError("before_event_id is read only with newest_first");
    }
    const int limit = request->limit() == 0 ? 1000 : request->limit();
    absl::StatusOr<std::vector<EventRecord>> events =
        request->newest_first()
            ? s_.coordinator->reads().ListEventsNewestFirst(request->job_id(), request->before_event_id(), limit)
            : s_.coordinator->reads().ListEvents(request->job_id(), request->after_event_id(), limit);
    if (!events.ok()) return events.status();
    response->mutable_events()->Reserve(static_cast<int>(events->size()));
    for (const EventRecord& e : *events) {
      pb::JobEvent* out = response->add_events();
      out->set_event_id(e.id);
      out->set_job_id(e.job_id);
      *out->mutable_time() = TimestampFromUnixMs(e.unix_ms);
      out->set_kind(e.kind);
      out->set_detail_json(e.detail_json);
    }
    return absl::OkStatus();
  });
}

grpc::ServerWriteReactor<pb::JobUpdate>* JobServiceImpl::WatchJob(grpc::CallbackServerContext* context,
                                                                  const pb::WatchJobRequest* request) {
  absl::Status admitted = AdmitCall(*context, s_, Role::kRead, "WatchJob");
  if (admitted.ok() && request->job_id() <= 0) admitted = absl::InvalidArgumentError("job_id must be a positive job id");
  if (!admitted.ok()) {
    auto* refused = new RefusedStream<pb::JobUpdate>();
    refused->Finish(ToGrpcStatus(admitted));
    return refused;
  }
  return JobWatchReactor::Start(s_, request->job_id(), request->include_map());
}

}  // namespace surfmap
