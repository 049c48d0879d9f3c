#include "clients/sim/rig/simulated_rig.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "clients/sim/rig/scene_surface.h"
#include "server/base/splitmix64.h"

namespace surfmap {
namespace {

// A drag that cannot go on along the surface: OUT_OF_RANGE is the mesh
// module's "leaves the open boundary"; INTERNAL "stuck" is what a walk
// straight into a boundary edge can report instead (seen on the plate).
bool IsBlockedPath(const absl::Status& s) { return absl::IsOutOfRange(s) || absl::IsInternal(s); }

absl::Status WithContext(const absl::Status& s, std::string_view context) {
  return absl::Status(s.code(), absl::StrCat(std::string(context), ": ", s.message()));
}

// A probe's tip rounds a sharp edge: the contact normal turns with the path
// as it goes over. On a facets scene the path crosses each edge on a level's
// chamfer, where the normals interpolated from the two faces' vertices lag
// the chord by up to 45 degrees (the drag simulator refuses more than ~17):
// each normal is made perpendicular to the path's local direction. On a
// face, where path and normal already agree, this changes nothing.
void TurnNormalsWithThePath(DragGeometry& geometry) {
  const std::vector<Eigen::Vector3d>& p = geometry.points;
  const std::size_t n = p.size();
  if (n < 2) return;
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d along = p[std::min(i + 1, n - 1)] - p[i == 0 ? 0 : i - 1];
    if (!(along.norm() > 0.0)) continue;
    const Eigen::Vector3d t = along.normalized();
    Eigen::Vector3d& normal = geometry.normals[i];
    const Eigen::Vector3d turned = normal - normal.dot(t) * t;
    if (turned.norm() > 1e-9) normal = turned.normalized();
  }
}

}  // namespace

bool SimulatedRigOptions::IsValid(std::string* why) const {
  auto fail = [why](std::string message) {
    if (why != nullptr) *why = std::move(message);
    return false;
  };
  if (surface_level < 1 || surface_level > 5) {
    return fail(absl::StrCat("surface_level ", surface_level, " is not in 1..5"));
  }
  if (!(path_step_mm > 0.0 && path_step_mm <= 2.0)) {
    return fail(absl::StrCat("path_step_mm ", path_step_mm, " is not in (0, 2]"));
  }
  if (!(max_approach_mm > 0.0)) return fail(absl::StrCat("max_approach_mm ", max_approach_mm, " must be > 0"));
  if (!(min_segment_mm > 0.0)) return fail(absl::StrCat("min_segment_mm ", min_segment_mm, " must be > 0"));
  std::string sim_why;
  if (!simulation.IsValid(&sim_why)) return fail(absl::StrCat("simulation: ", sim_why));
  return true;
}

SimulatedRig::SimulatedRig(Scene scene, SimulatedRigOptions options, std::unique_ptr<LoopSurface> surface)
    : scene_(std::move(scene)),
      options_(std::move(options)),
      surface_(std::move(surface)),
      material_(SceneMaterialField(scene_)) {}

absl::StatusOr<std::unique_ptr<SimulatedRig>> SimulatedRig::Create(Scene scene, const SimulatedRigOptions& options) {
  std::string why;
  if (!options.IsValid(&why)) return absl::InvalidArgumentError(absl::StrCat("simulated rig options: ", why));
  if (scene.materials.empty()) {
    return absl::InvalidArgumentError(absl::StrCat("scene '", scene.name, "' has no materials"));
  }
  // A dense scan is touched at a coarser level (its Loop limit lies within
  // its own bumps of it) rather than refused.
  absl::StatusOr<std::unique_ptr<LoopSurface>> surface = SceneSurface(scene, options.surface_level);
  if (!surface.ok()) return surface.status();
  return std::unique_ptr<SimulatedRig>(new SimulatedRig(std::move(scene), options, *std::move(surface)));
}

std::uint64_t SimulatedRig::SeedFor(std::int64_t command_id) const {
  // SplitMix64: a bijective mix, so distinct inputs give distinct, well-spread seeds.
  return SplitMix64(SplitMix64(scene_.seed ^ SplitMix64(options_.seed)) ^ static_cast<std::uint64_t>(command_id));
}

absl::StatusOr<DragTrace> SimulatedRig::Execute(const ProbeRequest& request) {
  absl::StatusOr<ProbeExecution> execution = ExecuteDetailed(request);
  if (!execution.ok()) return execution.status();
  return std::move(execution->trace);
}

absl::StatusOr<ProbeExecution> SimulatedRig::ExecuteDetailed(const ProbeRequest& request) const {
  if (absl::Status s = ValidateProbeRequest(request); !s.ok()) return s;
  const std::string context = absl::StrCat("probe command ", request.command_id);

  const SurfacePoint contact = surface_->ClosestPoint(request.position);
  if (contact.triangle < 0 || contact.distance > options_.max_approach_mm) {
    return absl::FailedPreconditionError(absl::StrFormat(
        "%s: position (%.3f, %.3f, %.3f) is %.3f mm from the surface of scene '%s' (the rig reaches %.3f mm)",
        context, request.position.x(), request.position.y(), request.position.z(), contact.distance, scene_.name,
        options_.max_approach_mm));
  }

  ProbeExecution out;
  out.approach_distance_mm = contact.distance;
  const double wanted = request.segment_length_mm;
  // The measurement belongs to the site, so the segment is centred on it:
  // walk half a segment back along the surface and drag from there through the
  // site. Near an open boundary (no room behind) the drag starts at the site.
  Eigen::Vector3d start = contact.position;
  Eigen::Vector3d forward = request.drag_direction;
  if (absl::StatusOr<SurfacePath> back =
          surface_->TraceDragPath(contact.position, -request.drag_direction, 0.5 * wanted, options_.path_step_mm);
      back.ok() && back->points.size() >= 2) {
    start = back->points.back();
    forward = contact.position - start;
    if (scene_.facets) {
      // On a CAD part the walk back can fold over a sharp edge, and the
      // chord from its end to the site then leaves the start aside of the
      // drag's line (measured: 52 degrees, the drag missing the site):
      // retrace the walk's last step instead.
      const std::vector<Eigen::Vector3d>& walked = back->points;
      forward = walked[walked.size() - 2] - walked.back();
    }
    out.centred = true;
  }
  auto trace = [&](const Eigen::Vector3d& direction, double length) {
    return surface_->TraceDragPath(start, direction, length, options_.path_step_mm);
  };
  Eigen::Vector3d drag_direction = out.centred ? forward : request.drag_direction;

  absl::StatusOr<SurfacePath> path = trace(drag_direction, wanted);
  if (!path.ok() && IsBlockedPath(path.status()) && out.centred) {
    // No room ahead of the centred segment: start at the site instead, and
    // let the rules below reverse or shorten it.
    start = contact.position;
    drag_direction = request.drag_direction;
    out.centred = false;
    path = trace(drag_direction, wanted);
  }
  if (!path.ok() && IsBlockedPath(path.status())) {
    // An open boundary ahead: drag the other way, as a lab operator would.
    const absl::Status forward_status = path.status();
    path = trace(-drag_direction, wanted);
    if (path.ok()) {
      out.reversed = true;
      out.note = absl::StrCat("reversed the drag direction: ", forward_status.message());
    } else if (IsBlockedPath(path.status())) {
      // Too close to the boundary both ways: the longest drag that fits, by
      // bisection on the length (each trial is a cheap surface walk).
      double best_length = 0.0;
      bool best_reversed = false;
      for (bool reversed : {false, true}) {
        const Eigen::Vector3d dir = reversed ? Eigen::Vector3d(-drag_direction) : drag_direction;
        if (!trace(dir, options_.min_segment_mm).ok()) continue;
        double lo = options_.min_segment_mm, hi = wanted;
        for (int i = 0; i < 12 && hi - lo > 0.05; ++i) {
          const double mid = 0.5 * (lo + hi);
          (trace(dir, mid).ok() ? lo : hi) = mid;
        }
        if (lo > best_length) {
          best_length = lo;
          best_reversed = reversed;
        }
      }
      if (best_length <= 0.0) {
        return absl::FailedPreconditionError(absl::StrFormat(
            "%s: no drag of %.3f mm (the rig's minimum) fits on the surface in either direction at (%.3f, %.3f, "
            "%.3f): %s",
            context, options_.min_segment_mm, contact.position.x(), contact.position.y(), contact.position.z(),
            forward_status.message()));
      }
      path = trace(best_reversed ? Eigen::Vector3d(-drag_direction) : drag_direction, best_length);
      if (!path.ok()) return WithContext(path.status(), context);
      out.reversed = best_reversed;
      out.shortened = true;
      out.note = absl::StrFormat("shortened the drag from %.3f to %.3f mm%s: an open boundary is near both ways (%s)",
                                 wanted, best_length, best_reversed ? " and reversed its direction" : "",
                                 forward_status.message());
    }
  }
  if (!path.ok()) return WithContext(path.status(), context);

  DragGeometry geometry{path->points, path->normals};
  if (scene_.facets) TurnNormalsWithThePath(geometry);
  DragSimOptions sim = options_.simulation;
  sim.seed = SeedFor(request.command_id);
  sim.length_mm = std::min(path->length_mm, wanted);
  sim.speed_mm_s = request.speed_mm_s;
  sim.normal_force_n = request.normal_force_n;
  absl::StatusOr<DragSimResult> result = SimulateDrag(geometry, material_, sim);
  if (!result.ok()) return WithContext(result.status(), absl::StrCat(context, ": drag simulation"));

  out.trace = std::move(result->trace);
  out.path = *std::move(path);
  out.length_mm = sim.length_mm;
  out.seed = sim.seed;
  return out;
}

}  // namespace surfmap
