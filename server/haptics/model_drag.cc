#include "server/haptics/model_drag.h"

#include <algorithm>
#include <cmath>

#include "absl/strings/str_cat.h"

namespace surfmap::haptics {
namespace {

constexpr double kMaxSamples = 1e7;
constexpr double kMaxSteps = 1e6;

// Arc-length parametrisation of a polyline.
struct Polyline {
  std::vector<Eigen::Vector3d> points;
  std::vector<double> s;

  mutable size_t cursor = 1;  // the segment of the last call: callers walk in small steps

  Eigen::Vector3d At(double x, Eigen::Vector3d* tangent) const {
    size_t i = cursor;
    while (i + 1 < s.size() && s[i] < x) ++i;
    while (i > 1 && s[i - 1] > x) --i;
    cursor = i;
    const double seg = s[i] - s[i - 1];
    const double f = seg > 0 ? std::clamp((x - s[i - 1]) / seg, 0.0, 1.0) : 0.0;
    *tangent = (points[i] - points[i - 1]).normalized();
    return points[i - 1] + f * (points[i] - points[i - 1]);
  }
};

}  // namespace

bool ModelDragOptions::IsValid(std::string* why) const {
  auto fail = [&](const char* message) {
    if (why) *why = message;
    return false;
  };
  if (!std::isfinite(speed_mm_s) || speed_mm_s <= 0) return fail("speed_mm_s must be finite and > 0");
  if (!std::isfinite(sample_rate_hz) || sample_rate_hz <= 0) return fail("sample_rate_hz must be finite and > 0");
  if (!std::isfinite(normal_force_n) || normal_force_n <= 0) return fail("normal_force_n must be finite and > 0");
  if (!std::isfinite(pause_s) || pause_s < 0) return fail("pause_s must be finite and >= 0");
  return true;
}

absl::StatusOr<ModelDrag> RenderDragAlongPath(const TextureRenderer& renderer, const std::vector<Eigen::Vector3d>& path,
                                              const ModelDragOptions& options) {
  std::string why;
  if (!options.IsValid(&why)) return absl::InvalidArgumentError(absl::StrCat("drag options: ", why));
  Polyline line;
  for (size_t i = 0; i < path.size(); ++i) {
    if (!path[i].allFinite()) return absl::InvalidArgumentError(absl::StrCat("path point ", i, " is not finite"));
    if (!line.points.empty() && (path[i] - line.points.back()).norm() == 0) continue;
    line.s.push_back(line.points.empty() ? 0.0 : line.s.back() + (path[i] - line.points.back()).norm());
    line.points.push_back(path[i]);
  }
  if (line.points.size() < 2) return absl::InvalidArgumentError("the path needs two distinct points");
  const double length = line.s.back();
  const double step = options.speed_mm_s / options.sample_rate_hz;
  const double pass_samples = std::floor(length / step) + 1;
  const double pause_samples = std::floor(options.pause_s * options.sample_rate_hz);
  if (2 * pass_samples + pause_samples > kMaxSamples) {
    return absl::InvalidArgumentError(absl::StrCat("the drag would have more than ", kMaxSamples, " samples"));
  }

  ModelDrag out;
  const size_t total = static_cast<size_t>(2 * pass_samples + pause_samples);
  out.trace.samples.reserve(total);
  out.mu.reserve(total);
  out.roughness_n.reserve(total);
  out.arc_length_mm.reserve(total);
  out.region.reserve(total);
  ProbeState state;
  const double dt = 1.0 / options.sample_rate_hz;
  double t = 0.0;
  auto record = [&](const Eigen::Vector3d& p, const Eigen::Vector3d& velocity, DragPhase phase) -> absl::Status {
    const ContactSample c = renderer.Sample(state, p, velocity, options.normal_force_n);
    if (!c.in_contact) {
      return absl::FailedPreconditionError(absl::StrCat("the path leaves the model surface at (", p.x(), ", ", p.y(),
                                                        ", ", p.z(), "): ", c.surface.distance_mm, " mm away"));
    }
    DragSample sample;
    sample.t = t;
    sample.position = c.surface.position;
    sample.force = options.normal_force_n * c.surface.normal + c.tangential_force;
    sample.phase = phase;
    out.trace.samples.push_back(sample);
    out.mu.push_back(c.mu);
    out.roughness_n.push_back(phase == DragPhase::kPause ? 0.0 : c.roughness_n);
    out.arc_length_mm.push_back(c.arc_length_mm);
    out.region.push_back(c.region);
    t += dt;
    return absl::OkStatus();
  };
  Eigen::Vector3d tangent;
  const int n = static_cast<int>(pass_samples);
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d p = line.At(std::min(i * step, length), &tangent);
    if (absl::Status s = record(p, options.speed_mm_s * tangent, DragPhase::kForward); !s.ok()) return s;
  }
  const Eigen::Vector3d end = line.At(std::min((n - 1) * step, length), &tangent);
  for (int i = 0; i < static_cast<int>(pause_samples); ++i) {
    if (absl::Status s = record(end, Eigen::Vector3d::Zero(), DragPhase::kPause); !s.ok()) return s;
  }
  for (int i = n - 1; i >= 0; --i) {
    const Eigen::Vector3d p = line.At(std::min(i * step, length), &tangent);
    if (absl::Status s = record(p, -options.speed_mm_s * tangent, DragPhase::kReverse); !s.ok()) return s;
  }
  return out;
}

absl::StatusOr<std::vector<Eigen::Vector3d>> TraceModelPath(const TextureRenderer& renderer,
                                                            const Eigen::Vector3d& start,
                                                            const Eigen::Vector3d& direction, double length_mm,
                                                            double step_mm, int max_steps) {
  if (!direction.allFinite() || direction.norm() == 0) {
    return absl::InvalidArgumentError("the drag direction must be finite and non-zero");
  }
  if (!start.allFinite()) return absl::InvalidArgumentError("the start point is not finite");
  if (!(length_mm > 0) || !(step_mm > 0) || !std::isfinite(length_mm) || !std::isfinite(step_mm)) {
    return absl::InvalidArgumentError("length and step must be finite and > 0");
  }
  if (max_steps < 1 || max_steps > kMaxSteps) return absl::InvalidArgumentError("max_steps must be in 1..10^6");
  if (length_mm / step_mm > max_steps) {
    return absl::InvalidArgumentError(absl::StrCat("length / step = ", length_mm / step_mm, " is more than ",
                                                   max_steps, " path steps"));
  }
  ProbeState state;
  SurfaceLookup here = renderer.Locate(start, state);
  if (here.triangle < 0 || here.distance_mm > renderer.options().contact_distance_mm) {
    return absl::FailedPreconditionError(absl::StrCat("the start point is ", here.distance_mm,
                                                      " mm from the model surface (more than ",
                                                      renderer.options().contact_distance_mm, " mm)"));
  }
  Eigen::Vector3d dir = direction.normalized();
  dir -= dir.dot(here.normal) * here.normal;
  // ~0.06 degrees from the normal, as LoopSurface::TraceDragPath.
  if (dir.norm() < 1e-3) return absl::InvalidArgumentError("the drag direction is along the surface normal");
  dir.normalize();
  std::vector<Eigen::Vector3d> points = {here.position};
  double travelled = 0.0;
  while (travelled < length_mm - 1e-12) {
    const double h = std::min(step_mm, length_mm - travelled);
    const SurfaceLookup next = renderer.Locate(points.back() + h * dir, state);
    Eigen::Vector3d d = next.position - points.back();
    const double len = d.norm();
    if (len < 1e-9 * step_mm) break;  // stuck at an open boundary
    // Distance alone does not bound the loop: steps the surface shortens
    // (but not to nothing) could take arbitrarily many.
    if (static_cast<int>(points.size()) > max_steps) {
      return absl::FailedPreconditionError(absl::StrCat("the path took more than ", max_steps, " steps and covered ",
                                                        travelled, " of ", length_mm, " mm"));
    }
    points.push_back(next.position);
    travelled += len;
    // Carry the direction: the step actually taken, in the new tangent plane.
    d -= d.dot(next.normal) * next.normal;
    if (d.norm() > 0) dir = d.normalized();
  }
  return points;
}

}  // namespace surfmap::haptics
