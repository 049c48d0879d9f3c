#include "clients/rig/scene_guard.h"

#include "absl/strings/str_format.h"
#include "server/mesh/facets_surface.h"

namespace surfmap::rig {
namespace {

struct Box {
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(INFINITY), hi = Eigen::Vector3d::Constant(-INFINITY);
};

Box BoxOf(const std::vector<Eigen::Vector3d>& points) {
  Box box;
  for (const Eigen::Vector3d& p : points) {
    box.lo = box.lo.cwiseMin(p);
    box.hi = box.hi.cwiseMax(p);
  }
  return box;
}

std::string Describe(const MeshFingerprint& mesh) {
  const Box box = BoxOf(mesh.limit_positions);
  const Eigen::Vector3d size = mesh.limit_positions.empty() ? Eigen::Vector3d::Zero() : Eigen::Vector3d(box.hi - box.lo);
  return absl::StrFormat("%s: %d vertices, %d faces, %.4g x %.4g x %.4g mm", mesh.name, mesh.limit_positions.size(),
                         mesh.triangle_indices.size() / 3, size.x(), size.y(), size.z());
}

}  // namespace

absl::Status CompareMeshes(const MeshFingerprint& scene, const MeshFingerprint& object) {
  auto differ = [&](const std::string& what) {
    return absl::FailedPreconditionError(absl::StrFormat(
        "%s is not this simulated rig's scene (%s): %s; the simulated rig measures only its own scene's mesh "
        "(start surfmap-rig with the scene that was uploaded for this object)",
        Describe(object), Describe(scene), what));
  };
  if (scene.limit_positions.size() != object.limit_positions.size()) return differ("vertex counts differ");
  if (scene.triangle_indices != object.triangle_indices) return differ("faces differ");
  const Box box = BoxOf(scene.limit_positions);
  const double tolerance = kSameMeshRelativeTolerance * (box.hi - box.lo).norm() + 1e-12;
  for (std::size_t v = 0; v < scene.limit_positions.size(); ++v) {
    const double d = (scene.limit_positions[v] - object.limit_positions[v]).norm();
    if (!(d <= tolerance)) {
      return differ(absl::StrFormat("vertex %d is %.3g mm away from the scene's (tolerance %.3g mm)", v, d, tolerance));
    }
  }
  return absl::OkStatus();
}

MeshFingerprint LevelFingerprint(std::string name, const SurfaceLevel& level) {
  MeshFingerprint out{std::move(name), level.limit_positions, {}};
  out.triangle_indices.reserve(3 * level.triangles.size());
  for (const auto& t : level.triangles) out.triangle_indices.insert(out.triangle_indices.end(), t.begin(), t.end());
  return out;
}

absl::StatusOr<MeshFingerprint> SceneFingerprint(const SimulatedRig& rig) {
  const std::string name = absl::StrFormat("scene '%s'", rig.scene().name);
  if (!rig.scene().facets) return LevelFingerprint(name, rig.surface().level(0));
  // An object uploaded as facets serves its facets themselves as level 0
  // (ExactFacetsSurface, server/mesh/facets_surface.h); the rig drags the
  // facets refined and smoothed, so its own level 0 differs.
  absl::StatusOr<std::unique_ptr<LoopSurface>> served = ExactFacetsSurface(rig.scene().mesh, 0);
  if (!served.ok()) {
    return absl::InvalidArgumentError(
        absl::StrFormat("%s: cannot build the surface the service serves for its facets: %s", name,
                        served.status().message()));
  }
  return LevelFingerprint(name, (*served)->level(0));
}

absl::StatusOr<DragTrace> SceneGuardDriver::Execute(const ProbeRequest& request) {
  if (request.job_id != 0) {
    std::lock_guard<std::mutex> lock(mu_);
    auto it = checked_.find(request.job_id);
    if (it == checked_.end()) {
      absl::StatusOr<MeshFingerprint> object = fetch_(request.job_id);
      // A failed read is not cached: the next command tries again.
      if (!object.ok()) {
        return absl::UnavailableError(absl::StrFormat("reading job %d's object to check it: %s", request.job_id,
                                                      object.status().message()));
      }
      it = checked_.emplace(request.job_id, CompareMeshes(scene_, *object)).first;
    }
    if (!it->second.ok()) {
      return absl::AbortedError(absl::StrFormat("refusing job %d: %s", request.job_id, it->second.message()));
    }
  }
  return rig_.Execute(request);
}

}  // namespace surfmap::rig
