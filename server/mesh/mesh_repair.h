// Uploads take meshes as scanners and CAD tools write them: innocuous defects
// are repaired and reported, harmful ones rejected (ValidateControlMesh's
// messages). Stored objects are then strict, clean meshes in mm.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "absl/status/statusor.h"
#include "server/mesh/control_mesh.h"

namespace surfmap {

// One kind of repair and how often it was made.
struct MeshRepairNote {
  std::string kind;    // e.g. "duplicate_vertices_welded"
  int count = 0;
  std::string detail;  // in words, with the tolerance used
};

struct RepairedMesh {
  ControlMesh mesh;  // mm
  std::vector<MeshRepairNote> repairs;  // empty: the file was clean
};

// Vertices closer than this fraction of the bounding-box diagonal are welded:
// 0.2 um on a 200 mm object, far below any scanner's resolution and far above
// the rounding of float32 coordinates (6e-8 relative) that splits a vertex
// shared by facets written separately (STL).
inline constexpr double kWeldRelativeTolerance = 1e-6;

// Parses `bytes`, multiplies the coordinates by `mm_per_unit`, and repairs,
// in this order (each counted in the result):
//   polygons with a vertex repeated in a row: the repeat dropped (a polygon
//     left with < 3 vertices is dropped)
//   duplicate vertices: welded within kWeldRelativeTolerance
//   degenerate faces: faces that lost a vertex to the weld, or have zero area
//     (the validator's limit), removed
//   duplicate faces: the same three vertices again (either winding), removed
//   unreferenced vertices: removed (indices compacted)
// then validates. Still rejected (INVALID_ARGUMENT, naming the place):
// syntax, non-finite coordinates, out-of-range indices, a polygon repeating a
// vertex not in a row, non-manifold edges, inconsistent orientation, a mesh
// with no faces left. `mm_per_unit` must be finite and > 0.
absl::StatusOr<RepairedMesh> ParseAndRepairMesh(std::string_view bytes, MeshFormat format, std::string_view source,
                                                double mm_per_unit);

}  // namespace surfmap
