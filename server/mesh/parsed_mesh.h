// Internal to the mesh module: a control mesh as a reader produced it, with
// enough provenance to name the offending polygon of the source in messages.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "absl/functional/function_ref.h"
#include "absl/status/status.h"
#include "server/mesh/control_mesh.h"

namespace surfmap {

// Faces smaller than this fraction of the squared bounding-box diagonal count
// as zero-area: far below any real face, far above rounding noise of a
// collinear triple (~1e-16). The validator (mesh_validation.cc) refuses such a
// face; the repair (mesh_repair.cc) removes it first.
inline constexpr double kRelativeZeroFaceArea = 1e-10;

struct ParsedMesh {
  ControlMesh mesh;
  // For each triangle: where its polygon came from, e.g. "face on line 12"
  // (OBJ) or "face 7" (PLY). Same length as mesh.triangles.
  std::vector<std::string> triangle_origin;
  // Polygons that listed the same vertex twice in a row (e.g. "f 1 2 2 3", a
  // quad collapsed by the writer): the repeat was dropped before
  // triangulation. The first such polygon's origin, for messages.
  int polygons_with_repeated_vertex = 0;
  std::string first_repeated_vertex_polygon;
  int first_repeated_vertex_triangle = 0;           // the index its first triangle would have had
  std::vector<int> first_repeated_vertex_indices;  // as listed
  // Of those, polygons left with fewer than 3 distinct vertices (no face).
  int polygons_dropped = 0;
  // A polygon repeating a vertex NOT in a row (a pinched polygon) cannot be
  // triangulated into a manifold: kept as is, so validation rejects it.
};

// The checks of ValidateControlMesh, with `describe_triangle(t)` naming
// triangle t in messages (so a reader can point at the source line).
absl::Status ValidateTriangleMesh(const ControlMesh& mesh,
                                  absl::FunctionRef<std::string(int)> describe_triangle);

// Appends the fan triangulation (v0, vi, vi+1) of `polygon` to `out`, each
// triangle tagged with `origin`. The caller checks polygon.size() >= 3.
// Repeats in a row (cyclically) are dropped first and counted in `out`.
void AppendFanTriangles(const std::vector<int>& polygon, const std::string& origin, ParsedMesh& out);

}  // namespace surfmap
