// The control mesh of a Loop subdivision surface: a triangle mesh read from
// OBJ or PLY (ASCII or binary). Polygons are fan-triangulated on load.
#pragma once

#include <array>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>
#include "absl/status/statusor.h"

namespace surfmap {

struct ControlMesh {
  std::vector<Eigen::Vector3d> positions;     // mm
  std::vector<std::array<int, 3>> triangles;  // counter-clockwise seen from outside
};

enum class MeshFormat { kObj, kPly };

// Parses mesh bytes. `source` names the input in error messages (a file name
// or "upload"). Errors (INVALID_ARGUMENT): syntax, NaN/inf coordinates,
// out-of-range indices, empty mesh, then everything ValidateControlMesh rejects.
absl::StatusOr<ControlMesh> ParseControlMesh(std::string_view bytes, MeshFormat format,
                                             std::string_view source);

// Guesses the format from the first bytes ("ply" magic) and parses.
absl::StatusOr<ControlMesh> ParseControlMeshAuto(std::string_view bytes, std::string_view source);

// Rejects: empty mesh, non-finite coordinates, out-of-range or repeated
// indices in a face, degenerate (zero-area) faces, non-manifold edges (more
// than two faces on one edge), inconsistently oriented neighbours.
absl::Status ValidateControlMesh(const ControlMesh& mesh);

// Writes ASCII OBJ (used by scenes and tests).
std::string WriteObj(const ControlMesh& mesh);

}  // namespace surfmap
