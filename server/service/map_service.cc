#include <cmath>
#include <utility>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "server/haptics/export/simulate_drag_proto.h"
#include "server/service/grpc_services.h"
#include "server/service/proto_builders.h"
#include "server/service/proto_conversion.h"

namespace surfmap {
namespace {

constexpr double kMaxQueryCoordinateMm = 1e6;  // 1 km

}  // namespace

grpc::ServerUnaryReactor* MapServiceImpl::GetSample(grpc::CallbackServerContext* context,
                                                    const pb::GetSampleRequest* request,
                                                    pb::GetSampleResponse* response) {
  // Without the series: one indexed read. With them: the whole trace is read
  // and refitted, which is long for a large trace: on the pool.
  const bool series = request->include_series();
  return HandleUnaryInlineIf(!series, context, s_, Role::kRead, "GetSample", [this, request, response, series]() -> absl::Status {
    if (request->fit_version() < 0) return absl::InvalidArgumentError("fit_version must be >= 0 (0 = latest)");
    // The trace, its command and the fit from one snapshot; the samples only
    // when the series are asked for.
    absl::StatusOr<SampleRecord> record =
        s_.coordinator->reads().GetSample(request->trace_id(), request->fit_version(), series);
    if (!record.ok()) return record.status();
    absl::StatusOr<pb::Sample> sample = BuildSample(*record);
    if (!sample.ok()) return sample.status();
    *response->mutable_sample() = std::move(*sample);
    if (series) return AddRecomputedSeries(s_.coordinator->reads(), *record, response->mutable_sample());
    return absl::OkStatus();
  });
}

grpc::ServerUnaryReactor* MapServiceImpl::ListSamples(grpc::CallbackServerContext* context,
                                                      const pb::ListSamplesRequest* request,
                                                      pb::ListSamplesResponse* response) {
  // Every sample of a job: a bulk read, on the pool.
  return HandleUnaryOnPool(context, s_, Role::kRead, "ListSamples", [this, request, response]() -> absl::Status {
    if (request->fit_version() < 0) return absl::InvalidArgumentError("fit_version must be >= 0 (0 = latest)");
    absl::StatusOr<std::vector<SampleRecord>> samples =
        s_.coordinator->reads().ListSamples(request->job_id(), request->fit_version());
    if (!samples.ok()) return samples.status();
    return AppendSamples(*samples, response->mutable_samples());
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
    absl::StatusOr<std::vector<SampleRecord>> samples = s_.coordinator->reads().ListSamples(request->job_id(), 0);
    if (!samples.ok()) return samples.status();
    if (absl::Status s = FillMapLevel(*snapshot, level, *samples, request->job_id(), response->mutable_map()); !s.ok()) {
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
      // Objects are measured in mm near their origin; a point a kilometre
      // away is a unit or frame mistake, and squared distances of 1e155 mm
      // overflow to infinity inside the closest-point search.
      for (const auto& [axis, value] : {std::pair{"x", p.x()}, std::pair{"y", p.y()}, std::pair{"z", p.z()}}) {
        if (std::abs(value) > kMaxQueryCoordinateMm) {
          return absl::InvalidArgumentError(absl::StrFormat(
              "points[%d].%s = %g mm is outside -%g..%g mm (query points are in the object's frame, in mm)", i,
              axis, value, kMaxQueryCoordinateMm, kMaxQueryCoordinateMm));
        }
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
      out->set_region(value->region);
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

grpc::ServerUnaryReactor* MapServiceImpl::SimulateDrag(grpc::CallbackServerContext* context,
                                                       const pb::SimulateDragRequest* request,
                                                       pb::SimulateDragResponse* response) {
  // Builds the map level with its mesh (as GetMap) and a renderer over it: on the pool.
  return HandleUnaryOnPool(context, s_, Role::kRead, "SimulateDrag", [this, request, response]() -> absl::Status {
    // The request's own fields first: a bad one costs no map build.
    if (absl::StatusOr<haptics::SimulateDragSettings> settings = haptics::ValidateSimulateDragRequest(*request);
        !settings.ok()) {
      return settings.status();
    }
    absl::StatusOr<MapSnapshot> snapshot = s_.coordinator->Map(request->job_id());
    if (!snapshot.ok()) return snapshot.status();
    const int finest = snapshot->surface->max_level();
    const int level = request->has_level() ? request->level() : finest;
    if (level < 0 || level > finest) {
      return absl::InvalidArgumentError(absl::StrCat("level must be in 0..", finest, " (unset = finest), got ", level));
    }
    absl::StatusOr<std::vector<SampleRecord>> samples = s_.coordinator->reads().ListSamples(request->job_id(), 0);
    if (!samples.ok()) return samples.status();
    pb::GetMapResponse map;
    if (absl::Status s = FillMapLevel(*snapshot, level, *samples, request->job_id(), map.mutable_map()); !s.ok()) {
      return s;
    }
    absl::StatusOr<JobSnapshot> job = s_.coordinator->GetJob(request->job_id());
    if (!job.ok()) return job.status();
    FillMesh(snapshot->surface->level(level), level, job->params.object_id, map.mutable_mesh());
    absl::StatusOr<pb::SimulateDragResponse> drag = haptics::SimulateDragOnMap(map, *request);
    if (!drag.ok()) return drag.status();
    *response = *std::move(drag);
    return absl::OkStatus();
  });
}

}  // namespace surfmap
