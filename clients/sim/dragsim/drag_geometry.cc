#include "clients/sim/dragsim/drag_geometry.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <Eigen/Geometry>
#include "absl/strings/str_format.h"

namespace surfmap {
namespace {

int StepCount(double length_mm, double step_mm) {
  return std::max(1, static_cast<int>(std::ceil(length_mm / step_mm)));
}

}  // namespace

absl::Status ValidateDragGeometry(const DragGeometry& g) {
  if (g.points.size() < 2) {
    return absl::InvalidArgumentError(
        absl::StrFormat("drag geometry has %d point(s), needs at least 2", g.points.size()));
  }
  if (g.normals.size() != g.points.size()) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "drag geometry has %d points but %d normals", g.points.size(), g.normals.size()));
  }
  for (std::size_t i = 0; i < g.points.size(); ++i) {
    if (!g.points[i].allFinite() || !g.normals[i].allFinite()) {
      return absl::InvalidArgumentError(absl::StrFormat("drag geometry point %d is not finite", i));
    }
    if (std::abs(g.normals[i].norm() - 1.0) > 1e-6) {
      return absl::InvalidArgumentError(
          absl::StrFormat("drag geometry normal %d has length %.6g, not 1", i, g.normals[i].norm()));
    }
    if (i + 1 < g.points.size()) {
      const Eigen::Vector3d d = g.points[i + 1] - g.points[i];
      if (!(d.norm() > 0.0)) {
        return absl::InvalidArgumentError(
            absl::StrFormat("drag geometry points %d and %d coincide", i, i + 1));
      }
    }
    // A path traced on a mesh pairs chords with interpolated vertex normals:
    // on tight curvature they disagree by several degrees, which the sampler
    // absorbs (it makes the tangent perpendicular to the normal). Only a
    // normal far off the path's perpendicular (> ~17 deg) is an error. The
    // path's direction at a point is the chord through its neighbours: where
    // a path folds over a sharp edge its chords turn 45 degrees at a point
    // whose normal can be perpendicular to their mean only.
    const Eigen::Vector3d along =
        (g.points[std::min(i + 1, g.points.size() - 1)] - g.points[i == 0 ? 0 : i - 1]).normalized();
    if (std::abs(g.normals[i].dot(along)) > 0.3) {
      return absl::InvalidArgumentError(absl::StrFormat(
          "drag geometry normal %d is not perpendicular to the path (n . t = %.3f)", i, g.normals[i].dot(along)));
    }
  }
  return absl::OkStatus();
}

DragGeometry PlaneGeometry(const Eigen::Vector3d& start, const Eigen::Vector3d& direction,
                           const Eigen::Vector3d& normal, double length_mm, double step_mm) {
  const Eigen::Vector3d n = normal.normalized();
  const Eigen::Vector3d u = (direction - direction.dot(n) * n).normalized();
  const int steps = StepCount(length_mm, step_mm);
  DragGeometry g;
  g.points.reserve(steps + 1);
  g.normals.reserve(steps + 1);
  for (int i = 0; i <= steps; ++i) {
    g.points.push_back(start + (length_mm * i / steps) * u);
    g.normals.push_back(n);
  }
  return g;
}

DragGeometry TiltedPlaneGeometry(double tilt_deg, double length_mm, double step_mm) {
  const double a = tilt_deg * std::numbers::pi / 180.0;
  const Eigen::Vector3d n(std::sin(a), 0.0, std::cos(a));
  const Eigen::Vector3d u(std::cos(a), 0.0, -std::sin(a));
  return PlaneGeometry(-0.5 * length_mm * u, u, n, length_mm, step_mm);
}

DragGeometry CylinderGeometry(double radius_mm, double length_mm, double step_mm) {
  const double half = 0.5 * length_mm / radius_mm;
  const int steps = StepCount(length_mm, step_mm);
  DragGeometry g;
  g.points.reserve(steps + 1);
  g.normals.reserve(steps + 1);
  for (int i = 0; i <= steps; ++i) {
    const double phi = -half + 2.0 * half * i / steps;
    const Eigen::Vector3d n(std::sin(phi), 0.0, std::cos(phi));
    g.points.push_back(radius_mm * n);
    g.normals.push_back(n);
  }
  return g;
}

DragGeometry SphereGeometry(double radius_mm, double polar_deg, double length_mm,
                            double step_mm) {
  const double theta = polar_deg * std::numbers::pi / 180.0;
  const double ring = radius_mm * std::sin(theta);  // radius of the latitude circle
  const double half = 0.5 * length_mm / ring;
  const int steps = StepCount(length_mm, step_mm);
  DragGeometry g;
  g.points.reserve(steps + 1);
  g.normals.reserve(steps + 1);
  for (int i = 0; i <= steps; ++i) {
    const double phi = -half + 2.0 * half * i / steps;
    const Eigen::Vector3d n(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi),
                            std::cos(theta));
    g.points.push_back(radius_mm * n);
    g.normals.push_back(n);
  }
  return g;
}

GeometryPath::GeometryPath(const DragGeometry& geometry) : geometry_(geometry) {
  s_.resize(geometry.points.size());
  s_[0] = 0.0;
  for (std::size_t i = 1; i < s_.size(); ++i) {
    s_[i] = s_[i - 1] + (geometry.points[i] - geometry.points[i - 1]).norm();
  }
}

void GeometryPath::At(double s, Eigen::Vector3d* point, Eigen::Vector3d* normal,
                      Eigen::Vector3d* tangent) const {
  s = std::clamp(s, 0.0, s_.back());
  // Segment k holds s_[k] <= s <= s_[k + 1].
  std::size_t k = std::upper_bound(s_.begin(), s_.end(), s) - s_.begin();
  k = std::clamp<std::size_t>(k, 1, s_.size() - 1) - 1;
  const double w = (s - s_[k]) / (s_[k + 1] - s_[k]);
  const auto& p = geometry_.points;
  const auto& n = geometry_.normals;
  *point = (1.0 - w) * p[k] + w * p[k + 1];
  *normal = ((1.0 - w) * n[k] + w * n[k + 1]).normalized();
  // Tangent of the segment, made perpendicular to the interpolated normal so
  // the simulated friction stays in the tangent plane.
  const Eigen::Vector3d d = p[k + 1] - p[k];
  *tangent = (d - d.dot(*normal) * *normal).normalized();
}

}  // namespace surfmap
