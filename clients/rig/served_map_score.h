// `surfmap-rig score --job JOB`: a job's map scored on the scene's TRUE
// surface (clients/sim/rig/surface_score.h) through the real server: every point
// is read with QueryMap, so the score is of the map as the service answers
// it to any client, not of a file or of the vertices it was built on.
#pragma once

#include <cstdint>
#include <memory>

#include <grpcpp/grpcpp.h>
#include "absl/status/statusor.h"
#include "clients/remote/remote_call.h"
#include "clients/sim/rig/scene.h"
#include "clients/sim/rig/surface_score.h"

namespace surfmap::rig {

// The scorer's points and the dense level's vertices are fetched in batches
// of at most `batch` points per QueryMap call (the server's default limit is
// 10,000); the boundary bisection's few thousand points one call each.
// Errors: the scorer's, or the first failed QueryMap (prefixed "QueryMap: ").
absl::StatusOr<SurfaceScore> ScoreServedMap(const Scene& scene, const std::shared_ptr<grpc::Channel>& channel,
                                            const cli::RemoteOptions& remote, int64_t job_id,
                                            const SurfaceScoreOptions& options = {}, int batch = 10'000);

}  // namespace surfmap::rig
