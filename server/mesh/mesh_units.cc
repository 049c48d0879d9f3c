#include "server/mesh/mesh_units.h"

#include <Eigen/Geometry>
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"

namespace surfmap {

double MmPerUnit(LengthUnit unit) {
  switch (unit) {
    case LengthUnit::kMm: return 1.0;
    case LengthUnit::kCm: return 10.0;
    case LengthUnit::kM: return 1000.0;
    case LengthUnit::kIn: return 25.4;
  }
  return 1.0;
}

const char* LengthUnitName(LengthUnit unit) {
  switch (unit) {
    case LengthUnit::kMm: return "mm";
    case LengthUnit::kCm: return "cm";
    case LengthUnit::kM: return "m";
    case LengthUnit::kIn: return "in";
  }
  return "?";
}

absl::Status CheckObjectSize(const Eigen::Vector3d& extent_mm, const std::string& unit_text,
                             std::vector<std::string>* warnings) {
  const double largest = extent_mm.maxCoeff();
  const std::string size = absl::StrFormat("%.4g x %.4g x %.4g mm", extent_mm.x(), extent_mm.y(), extent_mm.z());
  if (largest < kMinExtentMm) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "object is implausibly small in %s: %s (largest extent %.4g mm, below %g mm, smaller than a probe tip); "
        "give the mesh's real units (units m / cm / in, or scale)",
        unit_text, size, largest, kMinExtentMm));
  }
  if (largest > kMaxExtentMm) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "object is implausibly large in %s: %s (largest extent %.4g mm, above %g mm, beyond any lab rig's reach); "
        "give the mesh's real units (units mm, or scale)",
        unit_text, size, largest, kMaxExtentMm));
  }
  if (largest < kWarnMinExtentMm) {
    warnings->push_back(absl::StrFormat(
        "object is small in %s: %s, largest extent below %g mm (one default drag); check the units", unit_text,
        size, kWarnMinExtentMm));
  } else if (largest > kWarnMaxExtentMm) {
    warnings->push_back(absl::StrFormat(
        "object is large in %s: %s, largest extent above %g mm (a large arm's reach); check the units", unit_text,
        size, kWarnMaxExtentMm));
  }
  return absl::OkStatus();
}

Eigen::Vector3d BoundingBoxSize(const ControlMesh& mesh) {
  if (mesh.positions.empty()) return Eigen::Vector3d::Zero();
  Eigen::Vector3d lo = mesh.positions[0], hi = mesh.positions[0];
  for (const Eigen::Vector3d& p : mesh.positions) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  return hi - lo;
}

double SurfaceArea(const ControlMesh& mesh) {
  double area = 0.0;
  for (const auto& t : mesh.triangles) {
    const Eigen::Vector3d& a = mesh.positions[t[0]];
    area += 0.5 * (mesh.positions[t[1]] - a).cross(mesh.positions[t[2]] - a).norm();
  }
  return area;
}

}  // namespace surfmap
