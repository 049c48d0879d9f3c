// Meshes like the ones scanners and CAD tools hand a lab, made in code so the
// tests own their data: a dense, slightly noisy closed scan of a pebble-like
// object, and writers for the forms it arrives in (OBJ in metres with stray
// vertices, binary and ASCII STL with every facet's own corners).
#pragma once

#include <cstdint>
#include <string>

#include "absl/status/statusor.h"
#include "server/mesh/control_mesh.h"

namespace surfmap {

struct ScanLikeOptions {
  Eigen::Vector3d radii{60.0, 45.0, 35.0};  // mm, an ellipsoid
  int subdivisions = 5;                     // icosphere: 20 x 4^5 = 20,480 faces, 10,242 vertices
  double bump_mm = 1.5;                     // smooth low-frequency bumps (a pebble, not a perfect ellipsoid)
  double noise_mm = 0.05;                   // per-vertex scanner noise along the radius
  std::uint64_t seed = 1;
};

// A closed, valid mesh in mm, counter-clockwise seen from outside.
absl::StatusOr<ControlMesh> MakeScanLikeMesh(const ScanLikeOptions& options = {});

// OBJ with coordinates divided by `mm_per_unit` (1000: metres), followed by
// `stray_vertices` vertices no face uses (scanners leave them).
std::string WriteObjScaled(const ControlMesh& mesh, double mm_per_unit, int stray_vertices);

// STL: every facet with its own three corners (float32 in binary), the facet
// normal from the winding; coordinates divided by `mm_per_unit`.
std::string WriteStlBinary(const ControlMesh& mesh, double mm_per_unit = 1.0);
std::string WriteStlAscii(const ControlMesh& mesh, double mm_per_unit = 1.0);

}  // namespace surfmap
