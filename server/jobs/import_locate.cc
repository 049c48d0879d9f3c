#include "server/jobs/import_locate.h"

#include <vector>

#include "absl/strings/str_cat.h"
#include "server/plan/drag_direction.h"

namespace surfmap {

absl::StatusOr<LocatedDrag> LocateImportedDrag(const DragTrace& trace, const LoopSurface& surface,
                                               const ProbeParameters& probe) {
  std::vector<Eigen::Vector3d> forward;
  for (size_t i = 0; i < trace.samples.size(); ++i) {
    const DragSample& d = trace.samples[i];
    if (!d.position.allFinite()) {
      return absl::InvalidArgumentError(absl::StrCat("malformed trace: sample ", i, " has a position that is not finite"));
    }
    if (d.phase == DragPhase::kForward) forward.push_back(d.position);
  }
  if (forward.empty()) return absl::InvalidArgumentError("malformed trace: no forward sample to locate the drag by");

  // The point halfway along the forward path (by arc length).
  double length = 0.0;
  for (size_t i = 1; i < forward.size(); ++i) length += (forward[i] - forward[i - 1]).norm();
  Eigen::Vector3d middle = forward.front();
  double walked = 0.0;
  for (size_t i = 1; i < forward.size(); ++i) {
    const double step = (forward[i] - forward[i - 1]).norm();
    if (walked + step >= 0.5 * length && step > 0.0) {
      middle = forward[i - 1] + (forward[i] - forward[i - 1]) * ((0.5 * length - walked) / step);
      break;
    }
    walked += step;
  }

  const SurfacePoint site = surface.ClosestPoint(middle);
  if (site.triangle < 0) return absl::FailedPreconditionError("the job's surface has no triangles to locate a drag on");
  LocatedDrag out;
  ProbeCommand& c = out.command;
  c.sequence = 0;
  c.attempt = 1;
  c.position = site.position;
  c.normal = site.normal.norm() > 0 ? Eigen::Vector3d(site.normal.normalized()) : Eigen::Vector3d::UnitZ();
  c.probe = probe;
  // The vertex of the site's triangle with the largest weight: the nearest
  // corner, a finest-level vertex.
  const std::array<int, 3>& tri = surface.finest().triangles[site.triangle];
  int corner = 0;
  site.barycentric.maxCoeff(&corner);
  c.site = SiteId{surface.max_level(), tri[corner]};
  // The forward chord in the tangent plane; a chord along the normal (or
  // none) has no direction: the default one, and the length or direction
  // checks say what is wrong with such a drag.
  const Eigen::Vector3d chord = forward.back() - forward.front();
  const Eigen::Vector3d tangent = chord - chord.dot(c.normal) * c.normal;
  c.drag_direction = tangent.norm() > 1e-9 * std::max(1.0, chord.norm()) ? Eigen::Vector3d(tangent.normalized())
                                                                          : TangentDragDirection(c.normal);
  return out;
}

SurfaceDistance FarthestFromSurface(const DragTrace& trace, const LoopSurface& surface) {
  SurfaceDistance out;
  for (size_t i = 0; i < trace.samples.size(); ++i) {
    const double d = surface.ClosestPoint(trace.samples[i].position).distance;
    if (d > out.max_mm) {
      out.max_mm = d;
      out.sample = static_cast<int>(i);
    }
  }
  return out;
}

}  // namespace surfmap
