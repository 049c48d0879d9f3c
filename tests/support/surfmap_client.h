// Client-side helpers for talking to a real surfmapd: one stub per service,
// contexts with deadlines and tokens, seeded probe requests, and readable
// status text for test failure messages.
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include <grpcpp/channel.h>
#include <grpcpp/client_context.h>
#include "absl/status/statusor.h"
#include "clients/sim/rig/rig_driver.h"
#include "proto/surfmap/v1/surfmap.grpc.pb.h"
#include "server/estimate/drag_trace.h"

namespace surfmap::itest {

namespace pb = ::surfmap::v1;

struct Stubs {
  explicit Stubs(const std::shared_ptr<grpc::Channel>& channel);
  std::unique_ptr<pb::ObjectService::Stub> objects;
  std::unique_ptr<pb::JobService::Stub> jobs;
  std::unique_ptr<pb::ProbeService::Stub> probe;
  std::unique_ptr<pb::MapService::Stub> maps;
  std::unique_ptr<pb::TraceService::Stub> traces;
};

// A context with a deadline (every client call has one) and, when `token` is
// not empty, `authorization: Bearer <token>`.
std::unique_ptr<grpc::ClientContext> Context(double deadline_s = 60.0, const std::string& token = "");

// "NOT_FOUND: job 7 does not exist" (or "OK").
std::string Describe(const grpc::Status& status);

// A file of the source tree (SURFMAP_SOURCE_DIR), e.g. "tests/data/meshes/bottle.obj".
std::string SourcePath(const std::string& relative);
absl::StatusOr<std::string> ReadFileBytes(const std::string& path);

// Uploads a mesh file. The status text of a failed RPC comes back as INTERNAL.
absl::StatusOr<pb::ObjectInfo> UploadMeshFile(Stubs& stubs, const std::string& name, const std::string& path,
                                              pb::MeshFormat format, const std::string& token = "");

// The rig's view of a command (rig::ProbeRequestFromCommand, as surfmap-rig
// sees it), with `seed_id` as ProbeRequest::command_id, which seeds the
// simulated rig: pass the command id, or a per-site number to make a trace
// independent of the order in which commands were issued.
absl::StatusOr<ProbeRequest> SeededProbeRequest(const pb::ProbeCommand& command, std::int64_t seed_id);
// A seed id that depends only on the site (its finest-level vertex index).
std::int64_t SiteSeedId(const pb::Site& site);

// Bit-for-bit equality of two traces' columns.
bool SameSamples(const pb::TraceSamples& a, const pb::TraceSamples& b, std::string* difference);

}  // namespace surfmap::itest
