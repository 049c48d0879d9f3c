// The length unit of an uploaded mesh, and whether the object's size in it is
// plausible for a part on a lab robot's table. Catches the commonest upload
// mistake: a scan in metres (an object 0.2 units tall) read as mm.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>
#include "absl/status/status.h"
#include "server/mesh/control_mesh.h"

namespace surfmap {

enum class LengthUnit { kMm, kCm, kM, kIn };

double MmPerUnit(LengthUnit unit);
const char* LengthUnitName(LengthUnit unit);

// Largest extent limits, mm. Below 2 mm no probe tip (~1-5 mm) can drag on
// it; above 10 m no lab rig reaches across it: refused. Below 20 mm (one
// default drag) or above 2 m (a large arm's reach): accepted with a warning.
inline constexpr double kMinExtentMm = 2.0;
inline constexpr double kMaxExtentMm = 10'000.0;
inline constexpr double kWarnMinExtentMm = 20.0;
inline constexpr double kWarnMaxExtentMm = 2'000.0;

// `extent_mm`: bounding-box size after scaling; `unit_text` names what the
// caller said ("m", "scale 0.5"). INVALID_ARGUMENT for an
// implausible size, naming the size and the units that would make it
// plausible; otherwise OK with any warnings appended to `warnings`.
absl::Status CheckObjectSize(const Eigen::Vector3d& extent_mm, const std::string& unit_text,
                             std::vector<std::string>* warnings);

Eigen::Vector3d BoundingBoxSize(const ControlMesh& mesh);
double SurfaceArea(const ControlMesh& mesh);  // mm^2

}  // namespace surfmap
