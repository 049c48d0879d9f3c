// The path of a drag on a surface: a dense polyline of surface points with
// unit outward normals, plus builders for analytic shapes. The simulated rig
// will build one from a path traced on a mesh.
#pragma once

#include <vector>

#include <Eigen/Core>
#include "absl/status/status.h"

namespace surfmap {

struct DragGeometry {
  std::vector<Eigen::Vector3d> points;   // mm, on the surface, in drag order
  std::vector<Eigen::Vector3d> normals;  // unit, outward, one per point
};

// OK when there are >= 2 points, as many normals, all finite, normals of unit
// length (+-1e-6), consecutive points distinct, and each normal perpendicular
// to the path within ~17 deg (|n . tangent| <= 0.3; the sampler makes the
// tangent exactly perpendicular) so the drag is along the surface.
absl::Status ValidateDragGeometry(const DragGeometry& geometry);

// A straight drag of `length_mm` from `start` along `direction` on the plane
// with normal `normal` (direction is projected into the plane and normalised).
DragGeometry PlaneGeometry(const Eigen::Vector3d& start, const Eigen::Vector3d& direction,
                           const Eigen::Vector3d& normal, double length_mm,
                           double step_mm = 0.02);

// The plane z = 0 tilted by `tilt_deg` about the y axis (normal
// (sin tilt, 0, cos tilt)); the drag runs up the slope, centred on the origin.
DragGeometry TiltedPlaneGeometry(double tilt_deg, double length_mm, double step_mm = 0.02);

// Around the circumference of a cylinder of `radius_mm` whose axis is the y
// axis, centred on the top line (0, 0, radius): the normal turns by
// length / radius radians (20 mm on r = 40 mm: 28.6 deg).
DragGeometry CylinderGeometry(double radius_mm, double length_mm, double step_mm = 0.02);

// Along the circle of latitude at `polar_deg` from the +z pole of a sphere of
// `radius_mm` centred on the origin: the normal turns and the path also curves
// within the tangent plane (it is not a geodesic).
DragGeometry SphereGeometry(double radius_mm, double polar_deg, double length_mm,
                            double step_mm = 0.02);

// Arc-length access to a geometry (validated first).
class GeometryPath {
 public:
  explicit GeometryPath(const DragGeometry& geometry);
  double length_mm() const { return s_.back(); }
  // Point, unit normal and unit tangent (direction of increasing s) at arc
  // length s, clamped to [0, length]; linear interpolation between points.
  void At(double s, Eigen::Vector3d* point, Eigen::Vector3d* normal,
          Eigen::Vector3d* tangent) const;

 private:
  const DragGeometry& geometry_;
  std::vector<double> s_;
};

}  // namespace surfmap
