#include "tests/support/surfmap_client.h"

#include <chrono>
#include <cstring>
#include <fstream>
#include <sstream>

#include "absl/strings/str_cat.h"
#include "clients/remote/remote_call.h"
#include "clients/rig/probe_conversion.h"

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


std::string Describe(const grpc::Status& status) {
  if (status.ok()) return "OK";
  return absl::StrCat(std::string(cli::StatusCodeName(status.error_code())), ": ", status.error_message());
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

absl::StatusOr<ProbeRequest> SeededProbeRequest(const pb::ProbeCommand& command, std::int64_t seed_id) {
  absl::StatusOr<ProbeRequest> request = rig::ProbeRequestFromCommand(command);
  if (request.ok()) request->command_id = seed_id;
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
