#include <algorithm>
#include <atomic>

#include "absl/strings/str_cat.h"
#include "server/service/grpc_services.h"
#include "server/service/proto_builders.h"
#include "server/service/proto_conversion.h"

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

// WatchJob: one reactor per stream. One write in flight at a time; changes
// that arrive while a write is in flight are coalesced into the next update,
// so a slow client costs one pending message, never a growing queue. Building
// an update (possibly with a map rebuild) runs on the worker pool, never on the
// thread that reported the change (the store's writer).
class JobWatchReactor final : public grpc::ServerWriteReactor<pb::JobUpdate> {
 public:
  JobWatchReactor(const ServiceContext& services, int64_t job_id, bool include_map)
      : s_(services), job_id_(job_id), include_map_(include_map), shared_(std::make_shared<Shared>()) {
    shared_->reactor = this;
  }

  void Start() {
    std::weak_ptr<Shared> weak = shared_;
    absl::StatusOr<int64_t> handle = s_.coordinator->Watch(job_id_, [weak] {
      if (std::shared_ptr<Shared> shared = weak.lock()) {
        std::lock_guard<std::mutex> lock(shared->mu);
        if (shared->reactor) shared->reactor->OnChangeLocked();
      }
    });
    std::lock_guard<std::mutex> lock(shared_->mu);
    if (!handle.ok()) {
      FinishLocked(ToGrpcStatus(handle.status()));
      return;
    }
    handle_ = *handle;
    OnChangeLocked();
  }

  void OnWriteDone(bool ok) override {
    std::lock_guard<std::mutex> lock(shared_->mu);
    writing_ = false;
    if (pending_finish_) {
      Finish(*pending_finish_);
      return;
    }
    if (!ok || final_sent_) {
      FinishLocked(grpc::Status::OK);  // the client went away, or the job ended
      return;
    }
    ScheduleLocked();
  }

  void OnCancel() override {
    std::lock_guard<std::mutex> lock(shared_->mu);
    FinishLocked(grpc::Status::CANCELLED);
  }

  void OnDone() override {
    if (handle_ != 0) s_.coordinator->Unwatch(job_id_, handle_);
    {
      std::lock_guard<std::mutex> lock(shared_->mu);
      shared_->reactor = nullptr;  // late listeners and pool tasks see it gone
    }
    delete this;
  }

 private:
  struct Shared {
    std::mutex mu;
    JobWatchReactor* reactor = nullptr;
  };

  void OnChangeLocked() {
    dirty_ = true;
    ScheduleLocked();
  }

  void ScheduleLocked() {
    if (writing_ || scheduled_ || finished_ || !dirty_) return;
    scheduled_ = true;
    std::shared_ptr<Shared> shared = shared_;
    bool queued = s_.pool->Submit([shared] {
      std::lock_guard<std::mutex> lock(shared->mu);
      if (shared->reactor) shared->reactor->WriteUpdateLocked();
    });
    if (!queued) scheduled_ = false;  // retried at the next change
  }

  void WriteUpdateLocked() {
    scheduled_ = false;
    if (writing_ || finished_ || !dirty_) return;
    dirty_ = false;
    // The end of the stream follows the durable job state, not the in-memory
    // plan (which runs ahead while the last trace's write is being committed):
    // the final update then carries every sample of the completed job. Read
    // first, so the samples read below include everything it counts.
    absl::StatusOr<JobRecord> durable = s_.coordinator->store()->GetJob(job_id_);
    if (!durable.ok()) {
      FinishLocked(ToGrpcStatus(durable.status()));
      return;
    }
    absl::StatusOr<JobSnapshot> job = s_.coordinator->GetJob(job_id_);
    if (!job.ok()) {
      FinishLocked(ToGrpcStatus(job.status()));
      return;
    }
    update_.Clear();
    *update_.mutable_job() = JobInfoToProto(*job);
    if (job->latest_sample) {
      absl::StatusOr<pb::Sample> latest = BuildSample(*job->latest_sample);
      if (!latest.ok()) {
        FinishLocked(ToGrpcStatus(latest.status()));
        return;
      }
      *update_.mutable_latest_sample() = std::move(*latest);
    }
    if (include_map_) {
      // An update without the map that was asked for would look like a job
      // with no samples: end the stream with the reason instead.
      absl::StatusOr<MapSnapshot> map = s_.coordinator->Map(job_id_);
      absl::Status filled = map.ok() ? FillMapLevel(s_.coordinator->store(), job_id_, *map,
                                                    map->surface->max_level(), update_.mutable_map())
                                     : map.status();
      if (!filled.ok()) {
        FinishLocked(ToGrpcStatus(filled));
        return;
      }
    }
    final_sent_ = durable->state == JobState::kCompleted || durable->state == JobState::kCancelled;
    update_.mutable_job()->set_state(JobStateToProto(durable->state));
    writing_ = true;
    StartWrite(&update_);
  }

  void FinishLocked(const grpc::Status& status) {
    if (finished_) return;
    finished_ = true;
    if (writing_) {
      pending_finish_ = status;
    } else {
      Finish(status);
    }
  }

  const ServiceContext s_;
  const int64_t job_id_;
  const bool include_map_;
  int64_t handle_ = 0;
  std::shared_ptr<Shared> shared_;
  pb::JobUpdate update_;
  bool writing_ = false, scheduled_ = false, dirty_ = false, finished_ = false, final_sent_ = false;
  std::optional<grpc::Status> pending_finish_;
};

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
    absl::StatusOr<JobSnapshot> job = s_.coordinator->CreateJob(*params);
    if (!job.ok()) return job.status();
    *response->mutable_job() = JobInfoToProto(*job);
    spdlog::info("rpc=CreateJob job_id={} object_id={} mode={} levels={}..{} initial_sites={}", job->record.id,
                 params->object_id, std::string(PlanModeName(params->mode)), params->coarsest_level, params->finest_level,
                 job->progress.pending + job->progress.issued);
    return absl::OkStatus();
  });
}

grpc::ServerUnaryReactor* JobServiceImpl::GetJob(grpc::CallbackServerContext* context, const pb::GetJobRequest* request,
                                                 pb::GetJobResponse* response) {
  return HandleUnary(context, s_, Role::kRead, "GetJob", [&]() -> absl::Status {
    absl::StatusOr<JobSnapshot> job = s_.coordinator->GetJob(request->job_id());
    if (!job.ok()) return job.status();
    *response->mutable_job() = JobInfoToProto(*job);
    return absl::OkStatus();
  });
}

grpc::ServerUnaryReactor* JobServiceImpl::ListJobs(grpc::CallbackServerContext* context,
                                                   const pb::ListJobsRequest* request, pb::ListJobsResponse* response) {
  return HandleUnary(context, s_, Role::kRead, "ListJobs", [&]() -> absl::Status {
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
  return HandleUnary(context, s_, Role::kSteer, method, [&]() -> absl::Status {
    absl::StatusOr<JobSnapshot> job = s_.coordinator->SetJobState(request->job_id(), target);
    if (!job.ok()) return job.status();
    *response->mutable_job() = JobInfoToProto(*job);
    spdlog::info("rpc={} job_id={} state={}", method, request->job_id(), std::string(JobStateName(target)));
    return absl::OkStatus();
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
  return HandleUnary(context, s_, Role::kRead, "GetPlan", [&]() -> absl::Status {
    PlanProgress progress;
    absl::StatusOr<std::vector<SiteRecord>> sites = s_.coordinator->PlanSites(request->job_id(), &progress);
    if (!sites.ok()) return sites.status();
    // Counted after the plan's snapshot; see JobCoordinator::AddLeasedCount.
    absl::StatusOr<LeasedCounts> leased = s_.coordinator->LeasedCommands(request->job_id(), progress);
    if (!leased.ok()) return leased.status();
    absl::StatusOr<MapSnapshot> map = s_.coordinator->Map(request->job_id());
    const SurfaceLevel* finest = map.ok() ? &map->surface->finest() : nullptr;
    response->set_job_id(request->job_id());
    *response->mutable_progress() = ProgressToProto(progress, &*leased);
    for (const SiteRecord& site : *sites) {
      pb::PlanSite* out = response->add_sites();
      out->mutable_site()->set_level(site.site.level);
      out->mutable_site()->set_vertex(site.site.vertex);
      out->set_state(SiteStateToProto(site.state));
      out->set_attempts(site.failures + (site.sequence != 0 ? 1 : 0));
      out->set_failure_reason(site.reason);
      if (finest && site.site.vertex < static_cast<int>(finest->limit_positions.size())) {
        *out->mutable_position() = ToProto(finest->limit_positions[site.site.vertex]);
      }
    }
    return absl::OkStatus();
  });
}

grpc::ServerWriteReactor<pb::JobUpdate>* JobServiceImpl::WatchJob(grpc::CallbackServerContext* context,
                                                                  const pb::WatchJobRequest* request) {
  auto* reactor = new JobWatchReactor(s_, request->job_id(), request->include_map());
  absl::Status admitted = s_.gate->Admit(*context, Role::kRead, "WatchJob");
  if (!admitted.ok()) {
    reactor->Finish(ToGrpcStatus(admitted));
    return reactor;
  }
  reactor->Start();
  return reactor;
}

}  // namespace surfmap
