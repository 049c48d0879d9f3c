#include "absl/strings/str_cat.h"
#include "server/service/grpc_services.h"
#include "server/service/proto_builders.h"
#include "server/service/proto_conversion.h"

namespace surfmap {

grpc::ServerUnaryReactor* MapServiceImpl::GetSample(grpc::CallbackServerContext* context,
                                                    const pb::GetSampleRequest* request,
                                                    pb::GetSampleResponse* response) {
  return HandleUnary(context, s_, Role::kRead, "GetSample", [&]() -> absl::Status {
    if (request->fit_version() < 0) return absl::InvalidArgumentError("fit_version must be >= 0 (0 = latest)");
    Store* store = s_.coordinator->store();
    // The samples only when the series are asked for: one read of the trace
    // and one of the fit either way.
    absl::StatusOr<TraceRecord> trace = store->GetTrace(request->trace_id(), request->include_series());
    if (!trace.ok()) return trace.status();
    absl::StatusOr<CommandRecord> command = store->GetCommand(trace->command_id);
    if (!command.ok()) return command.status();
    absl::StatusOr<FitRecord> fit = store->GetFit(trace->id, request->fit_version());
    if (!fit.ok()) return fit.status();
    absl::StatusOr<pb::Sample> sample = BuildSample(*trace, *command, *fit);
    if (!sample.ok()) return sample.status();
    *response->mutable_sample() = std::move(*sample);
    if (request->include_series()) return AddRecomputedSeries(*trace, *fit, response->mutable_sample());
    return absl::OkStatus();
  });
}

grpc::ServerUnaryReactor* MapServiceImpl::ListSamples(grpc::CallbackServerContext* context,
                                                      const pb::ListSamplesRequest* request,
                                                      pb::ListSamplesResponse* response) {
  return HandleUnary(context, s_, Role::kRead, "ListSamples", [&]() -> absl::Status {
    if (request->fit_version() < 0) return absl::InvalidArgumentError("fit_version must be >= 0 (0 = latest)");
    Store* store = s_.coordinator->store();
    if (absl::StatusOr<JobRecord> job = store->GetJob(request->job_id()); !job.ok()) return job.status();
    return AppendJobSamples(store, request->job_id(), request->fit_version(), response->mutable_samples());
  });
}

grpc::ServerUnaryReactor* MapServiceImpl::GetMap(grpc::CallbackServerContext* context, const pb::GetMapRequest* request,
                                                 pb::GetMapResponse* response) {
  return HandleUnaryOnPool(context, s_, Role::kRead, "GetMap", [this, request, response]() -> absl::Status {
    absl::StatusOr<MapSnapshot> snapshot = s_.coordinator->Map(request->job_id());
    if (!snapshot.ok()) return snapshot.status();
    const int finest = snapshot->surface->max_level();
    const int level = request->level() == -1 ? finest : request->level();
    if (level < 0 || level > finest) {
      return absl::InvalidArgumentError(absl::StrCat("level must be in 0..", finest, " or -1 (finest), got ", request->level()));
    }
    if (absl::Status s = FillMapLevel(s_.coordinator->store(), request->job_id(), *snapshot, level,
                                      response->mutable_map());
        !s.ok()) {
      return s;
    }
    if (request->include_mesh()) {
      absl::StatusOr<JobSnapshot> job = s_.coordinator->GetJob(request->job_id());
      if (!job.ok()) return job.status();
      FillMesh(snapshot->surface->level(level), level, job->params.object_id, response->mutable_mesh());
    }
    return absl::OkStatus();
  });
}

grpc::ServerUnaryReactor* MapServiceImpl::QueryMap(grpc::CallbackServerContext* context,
                                                   const pb::QueryMapRequest* request,
                                                   pb::QueryMapResponse* response) {
  // A query after new samples rebuilds the map first: on the pool.
  return HandleUnaryOnPool(context, s_, Role::kRead, "QueryMap", [this, request, response]() -> absl::Status {
    if (request->points_size() == 0) return absl::InvalidArgumentError("points is empty");
    if (request->points_size() > s_.config->max_query_points) {
      return absl::ResourceExhaustedError(
          absl::StrCat(request->points_size(), " query points; the limit is ", s_.config->max_query_points));
    }
    for (int i = 0; i < request->points_size(); ++i) {
      const pb::Vec3& p = request->points(i);
      if (!std::isfinite(p.x()) || !std::isfinite(p.y()) || !std::isfinite(p.z())) {
        return absl::InvalidArgumentError(absl::StrCat("points[", i, "] is not finite"));
      }
    }
    absl::StatusOr<MapSnapshot> snapshot = s_.coordinator->Map(request->job_id());
    if (!snapshot.ok()) return snapshot.status();
    if (!snapshot->map) {
      return absl::FailedPreconditionError(absl::StrCat("job ", request->job_id(), " has no measured sample yet"));
    }
    response->mutable_values()->Reserve(request->points_size());
    for (const pb::Vec3& p : request->points()) {
      SurfacePoint point = snapshot->surface->ClosestPoint(FromProto(p));
      absl::StatusOr<MapValue> value = snapshot->map->ValueAt(point);
      if (!value.ok()) return value.status();
      pb::MapValue* out = response->add_values();
      *out->mutable_surface_point() = ToProto(point.position);
      *out->mutable_normal() = ToProto(point.normal);
      out->set_distance_mm(point.distance);
      out->set_mu(value->mu);
      out->set_mu_uncertainty(value->mu_std);
      if (value->has_roughness) {
        std::vector<double> a = ReflectionToAr(value->reflection);
        out->set_sigma(value->sigma);
        out->set_a1(a.size() > 0 ? a[0] : 0.0);
        out->set_a2(a.size() > 1 ? a[1] : 0.0);
      }
    }
    return absl::OkStatus();
  });
}

}  // namespace surfmap
