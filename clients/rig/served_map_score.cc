#include "clients/rig/served_map_score.h"

#include <algorithm>
#include <cstring>
#include <string>
#include <unordered_map>
#include <vector>

#include "absl/strings/str_cat.h"
#include "proto/surfmap/v1/surfmap.grpc.pb.h"

namespace surfmap::rig {
namespace {

namespace pb = ::surfmap::v1;

// Points are looked up by their exact bits: the scorer asks for the very
// points it handed out.
std::string Key(const Eigen::Vector3d& p) {
  std::string key(sizeof(double) * 3, '\0');
  std::memcpy(key.data(), p.data(), key.size());
  return key;
}

MapReading ReadingOf(const pb::MapValue& v) {
  MapReading r;
  r.mu = v.mu();
  r.has_roughness = v.sigma() > 0.0;
  r.a1 = v.a1();
  r.a2 = v.a2();
  r.sigma = v.sigma();
  return r;
}

class ServedMapReader {
 public:
  ServedMapReader(const std::shared_ptr<grpc::Channel>& channel, const cli::RemoteOptions& remote, int64_t job_id)
      : stub_(pb::MapService::NewStub(channel)), remote_(remote), job_id_(job_id) {}

  absl::Status Fetch(const std::vector<Eigen::Vector3d>& points, int batch) {
    for (size_t start = 0; start < points.size(); start += batch) {
      const size_t end = std::min(points.size(), start + static_cast<size_t>(batch));
      absl::StatusOr<std::vector<MapReading>> readings = Query({points.begin() + start, points.begin() + end});
      if (!readings.ok()) return readings.status();
      for (size_t i = start; i < end; ++i) cache_[Key(points[i])] = (*readings)[i - start];
    }
    return absl::OkStatus();
  }

  absl::StatusOr<MapReading> Read(const Eigen::Vector3d& p) {
    auto it = cache_.find(Key(p));
    if (it != cache_.end()) return it->second;
    absl::StatusOr<std::vector<MapReading>> one = Query({p});
    if (!one.ok()) return one.status();
    return one->front();
  }

 private:
  absl::StatusOr<std::vector<MapReading>> Query(const std::vector<Eigen::Vector3d>& points) {
    pb::QueryMapRequest request;
    request.set_job_id(job_id_);
    for (const Eigen::Vector3d& p : points) {
      pb::Vec3* v = request.add_points();
      v->set_x(p.x());
      v->set_y(p.y());
      v->set_z(p.z());
    }
    pb::QueryMapResponse response;
    grpc::ClientContext context;
    cli::PrepareContext(remote_, &context);
    const grpc::Status status = stub_->QueryMap(&context, request, &response);
    if (!status.ok()) {
      return absl::Status(static_cast<absl::StatusCode>(status.error_code()),
                          absl::StrCat("QueryMap: ", status.error_message()));
    }
    if (response.values_size() != static_cast<int>(points.size())) {
      return absl::DataLossError(absl::StrCat("QueryMap: ", response.values_size(), " values for ", points.size(),
                                              " points"));
    }
    std::vector<MapReading> out;
    out.reserve(points.size());
    for (const pb::MapValue& v : response.values()) out.push_back(ReadingOf(v));
    return out;
  }

  std::unique_ptr<pb::MapService::Stub> stub_;
  cli::RemoteOptions remote_;
  int64_t job_id_;
  std::unordered_map<std::string, MapReading> cache_;
};

}  // namespace

absl::StatusOr<SurfaceScore> ScoreServedMap(const Scene& scene, const std::shared_ptr<grpc::Channel>& channel,
                                            const cli::RemoteOptions& remote, int64_t job_id,
                                            const SurfaceScoreOptions& options, int batch) {
  if (batch < 1) return absl::InvalidArgumentError("batch must be >= 1");
  absl::StatusOr<SurfaceScorer> scorer = SurfaceScorer::Create(scene, options);
  if (!scorer.ok()) return scorer.status();
  ServedMapReader reader(channel, remote, job_id);
  if (absl::Status s = reader.Fetch(scorer->points(), batch); !s.ok()) return s;
  if (absl::Status s = reader.Fetch(scorer->dense_vertices(), batch); !s.ok()) return s;
  return scorer->Score([&reader](const Eigen::Vector3d& p) { return reader.Read(p); });
}

}  // namespace surfmap::rig
