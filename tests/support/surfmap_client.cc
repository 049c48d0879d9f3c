#include "tests/support/surfmap_client.h"

#include <chrono>
#include <cstring>
#include <fstream>
#include <sstream>

#include "absl/strings/str_cat.h"

#ifndef SURFMAP_SOURCE_DIR
#define SURFMAP_SOURCE_DIR "."
#endif

namespace surfmap::itest {

Stubs::Stubs(const std::shared_ptr<grpc::Channel>& channel)
    : objects(pb::ObjectService::NewStub(channel)),
      jobs(pb::JobService::NewStub(channel)),
      probe(pb::ProbeService::NewStub(channel)),
      maps(pb::MapService::NewStub(channel)),
      traces(pb::TraceService::NewStub(channel)) {}

std::unique_ptr<grpc::ClientContext> Context(double deadline_s, const std::string& token) {
  auto context = std::make_unique<grpc::ClientContext>();
  context->set_deadline(std::chrono::system_clock::now() +
                        std::chrono::microseconds(static_cast<int64_t>(deadline_s * 1e6)));
  if (!token.empty()) context->AddMetadata("authorization", "Bearer " + token);
  return context;
}

const char* CodeName(grpc::StatusCode code) {
  switch (code) {
    case grpc::StatusCode::OK: return "OK";
    case grpc::StatusCode::CANCELLED: return "CANCELLED";
    case grpc::StatusCode::UNKNOWN: return "UNKNOWN";
    case grpc::StatusCode::INVALID_ARGUMENT: return "INVALID_ARGUMENT";
    case grpc::StatusCode::DEADLINE_EXCEEDED: return "DEADLINE_EXCEEDED";
    case grpc::StatusCode::NOT_FOUND: return "NOT_FOUND";
    case grpc::StatusCode::ALREADY_EXISTS: return "ALREADY_EXISTS";
    case grpc::StatusCode::PERMISSION_DENIED: return "PERMISSION_DENIED";
    case grpc::StatusCode::RESOURCE_EXHAUSTED: return "RESOURCE_EXHAUSTED";
    case grpc::StatusCode::FAILED_PRECONDITION: return "FAILED_PRECONDITION";
    case grpc::StatusCode::ABORTED: return "ABORTED";
    case grpc::StatusCode::OUT_OF_RANGE: return "OUT_OF_RANGE";
    case grpc::StatusCode::UNIMPLEMENTED: return "UNIMPLEMENTED";
    case grpc::StatusCode::INTERNAL: return "INTERNAL";
    case grpc::StatusCode::UNAVAILABLE: return "UNAVAILABLE";
    case grpc::StatusCode::DATA_LOSS: return "DATA_LOSS";
    case grpc::StatusCode::UNAUTHENTICATED: return "UNAUTHENTICATED";
    default: return "UNKNOWN_CODE";
  }
}

std::string Describe(const grpc::Status& status) {
  if (status.ok()) return "OK";
  return absl::StrCat(CodeName(status.error_code()), ": ", status.error_message());
}

std::string SourcePath(const std::string& relative) { return std::string(SURFMAP_SOURCE_DIR) + "/" + relative; }

absl::StatusOr<std::string> ReadFileBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return absl::NotFoundError(absl::StrCat("cannot open ", path));
  std::ostringstream bytes;
  bytes << in.rdbuf();
  return bytes.str();
}

absl::StatusOr<pb::ObjectInfo> UploadMeshFile(Stubs& stubs, const std::string& name, const std::string& path,
                                              pb::MeshFormat format, const std::string& token) {
  absl::StatusOr<std::string> bytes = ReadFileBytes(path);
  if (!bytes.ok()) return bytes.status();
  pb::UploadObjectRequest request;
  request.set_name(name);
  request.set_format(format);
  request.set_mesh(*bytes);
  pb::UploadObjectResponse response;
  grpc::Status status = stubs.objects->UploadObject(Context(120, token).get(), request, &response);
  if (!status.ok()) return absl::InternalError(absl::StrCat("UploadObject(", path, "): ", Describe(status)));
  return response.object();
}

pb::TraceSamples TraceToProto(const DragTrace& trace) {
  pb::TraceSamples out;
  const int n = static_cast<int>(trace.samples.size());
  for (auto* column : {out.mutable_t(), out.mutable_x(), out.mutable_y(), out.mutable_z(), out.mutable_fx(),
                       out.mutable_fy(), out.mutable_fz()}) {
    column->Reserve(n);
  }
  out.mutable_phases()->Reserve(n);
  for (const DragSample& s : trace.samples) {
    out.add_t(s.t);
    out.add_x(s.position.x());
    out.add_y(s.position.y());
    out.add_z(s.position.z());
    out.add_fx(s.force.x());
    out.add_fy(s.force.y());
    out.add_fz(s.force.z());
    out.add_phases(s.phase == DragPhase::kForward ? pb::PHASE_FORWARD
                   : s.phase == DragPhase::kPause ? pb::PHASE_PAUSE
                                                  : pb::PHASE_REVERSE);
  }
  return out;
}

DragTrace TraceFromProto(const pb::TraceSamples& samples) {
  DragTrace trace;
  const int n = samples.t_size();
  trace.samples.resize(n);
  for (int i = 0; i < n; ++i) {
    DragSample& s = trace.samples[i];
    s.t = samples.t(i);
    s.position = {samples.x(i), samples.y(i), samples.z(i)};
    s.force = {samples.fx(i), samples.fy(i), samples.fz(i)};
    s.phase = samples.phases(i) == pb::PHASE_FORWARD ? DragPhase::kForward
              : samples.phases(i) == pb::PHASE_PAUSE ? DragPhase::kPause
                                                     : DragPhase::kReverse;
  }
  return trace;
}

ProbeRequest ProbeRequestFromCommand(const pb::ProbeCommand& command, std::int64_t seed_id) {
  ProbeRequest request;
  request.position = {command.position().x(), command.position().y(), command.position().z()};
  request.normal = {command.normal().x(), command.normal().y(), command.normal().z()};
  request.drag_direction = {command.drag_direction().x(), command.drag_direction().y(),
                            command.drag_direction().z()};
  // Zero fields mean "the default" in the API; the rig wants explicit values.
  if (command.probe().segment_length_mm() > 0) request.segment_length_mm = command.probe().segment_length_mm();
  if (command.probe().speed_mm_s() > 0) request.speed_mm_s = command.probe().speed_mm_s();
  if (command.probe().normal_force_n() > 0) request.normal_force_n = command.probe().normal_force_n();
  request.command_id = seed_id;
  return request;
}

std::int64_t SiteSeedId(const pb::Site& site) { return 1'000'000 + site.vertex(); }

bool SameSamples(const pb::TraceSamples& a, const pb::TraceSamples& b, std::string* difference) {
  auto same_doubles = [&](const auto& x, const auto& y, const char* name) {
    if (x.size() != y.size()) {
      *difference = absl::StrCat(name, ": ", x.size(), " vs ", y.size(), " values");
      return false;
    }
    for (int i = 0; i < x.size(); ++i) {
      double u = x.Get(i), v = y.Get(i);
      if (std::memcmp(&u, &v, sizeof(double)) != 0) {
        *difference = absl::StrCat(name, "[", i, "]: ", u, " vs ", v);
        return false;
      }
    }
    return true;
  };
  if (!same_doubles(a.t(), b.t(), "t") || !same_doubles(a.x(), b.x(), "x") || !same_doubles(a.y(), b.y(), "y") ||
      !same_doubles(a.z(), b.z(), "z") || !same_doubles(a.fx(), b.fx(), "fx") ||
      !same_doubles(a.fy(), b.fy(), "fy") || !same_doubles(a.fz(), b.fz(), "fz")) {
    return false;
  }
  if (a.phases_size() != b.phases_size()) {
    *difference = absl::StrCat("phases: ", a.phases_size(), " vs ", b.phases_size(), " values");
    return false;
  }
  for (int i = 0; i < a.phases_size(); ++i) {
    if (a.phases(i) != b.phases(i)) {
      *difference = absl::StrCat("phases[", i, "]: ", a.phases(i), " vs ", b.phases(i));
      return false;
    }
  }
  return true;
}

}  // namespace surfmap::itest
