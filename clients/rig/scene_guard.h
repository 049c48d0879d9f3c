// The simulated rig must only measure its own scene: a job whose object is a
// different mesh would get traces of the wrong object, planted in its map
// without a word. SceneGuardDriver checks each job's object once, before the
// first drag for it, against the scene's mesh (vertex and face counts, the
// faces, and every vertex's limit position within a tolerance, so an upload
// in metres or inches of the same mesh still matches), and refuses with a
// message naming both meshes.
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <mutex>
#include <string>
#include <vector>

#include <Eigen/Core>
#include "absl/status/statusor.h"
#include "clients/sim/rig/rig_driver.h"
#include "clients/sim/rig/simulated_rig.h"

namespace surfmap::rig {

// An object's level-0 surface as the server and the rig both compute it.
struct MeshFingerprint {
  std::string name;  // for messages
  std::vector<Eigen::Vector3d> limit_positions;
  std::vector<int> triangle_indices;  // 3 per triangle
};

// Vertices may differ by this fraction of the bounding-box diagonal: the
// rounding of a unit conversion (1e-15 relative), far below any real change.
inline constexpr double kSameMeshRelativeTolerance = 1e-9;

// OK when `object` is `scene`'s mesh; FAILED_PRECONDITION naming the first
// difference (counts, bounding box, a vertex) otherwise.
absl::Status CompareMeshes(const MeshFingerprint& scene, const MeshFingerprint& object);

// The fingerprint of a surface level (its limit positions and triangles).
MeshFingerprint LevelFingerprint(std::string name, const SurfaceLevel& level);

// The scene's fingerprint: level 0 of the rig's own surface, or for a facets
// scene level 0 as the service serves an object uploaded as facets
// (INVALID_ARGUMENT naming the scene when that cannot be built).
absl::StatusOr<MeshFingerprint> SceneFingerprint(const SimulatedRig& rig);

class SceneGuardDriver : public RigDriver {
 public:
  // `fetch(job_id)` reads the job's object from the server.
  using FetchObject = std::function<absl::StatusOr<MeshFingerprint>(std::int64_t job_id)>;
  SceneGuardDriver(RigDriver& rig, MeshFingerprint scene, FetchObject fetch)
      : rig_(rig), scene_(std::move(scene)), fetch_(std::move(fetch)) {}

  // ABORTED (the rig loop reports the command and stops) for a job whose
  // object is not the scene's mesh; the fetch's error for an unreadable one.
  absl::StatusOr<DragTrace> Execute(const ProbeRequest& request) override;

 private:
  RigDriver& rig_;
  const MeshFingerprint scene_;
  const FetchObject fetch_;
  std::mutex mu_;
  std::map<std::int64_t, absl::Status> checked_;  // job id -> verdict
};

}  // namespace surfmap::rig
