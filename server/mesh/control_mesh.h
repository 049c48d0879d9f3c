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

enum class MeshFormat { kObj, kPly, kStl };

// Parses mesh bytes. `source` names the input in error messages (a file name
// or "upload"). Errors (INVALID_ARGUMENT): syntax, NaN/inf coordinates,
// out-of-range indices, empty mesh, then everything ValidateControlMesh rejects.
// Every message starts with `source` and names the place: OBJ line, PLY header
// line, ASCII data line or binary element and byte offset, and for topology
// errors "triangle t (face on line n)" / "triangle t (face f)".
// OBJ: `v` and `f` records (1-based or negative indices, v/vt/vn forms);
// everything else is ignored. Read with tinyobjloader in double precision,
// coordinates checked by a strict pre-scan (tinyobjloader reads "nan" as 0).
// PLY: format ascii / binary_little_endian / binary_big_endian 1.0; element
// vertex with float/double x, y, z; element face with an integer list
// vertex_indices (or vertex_index); other elements and properties, lists
// included, are skipped. Data must end exactly after the last element.
// STL: ASCII or binary (stl_reader.h); bit-identical corners are one vertex.
absl::StatusOr<ControlMesh> ParseControlMesh(std::string_view bytes, MeshFormat format,
                                             std::string_view source);

// Guesses the format from the first bytes ("ply" magic) and parses.
absl::StatusOr<ControlMesh> ParseControlMeshAuto(std::string_view bytes, std::string_view source);
// PLY by its magic, STL binary by its size or ASCII by "solid", else OBJ.
MeshFormat GuessMeshFormat(std::string_view bytes);

// Rejects: empty mesh, non-finite coordinates, out-of-range or repeated
// indices in a face, unreferenced vertices (they would be sampling sites with
// no surface), degenerate faces (area below 1e-10 of the squared bounding-box
// diagonal), non-manifold edges (more than two faces on one edge),
// inconsistently oriented neighbours. Open meshes (boundary edges with one
// face) are valid. Messages name the vertex, triangle or edge.
absl::Status ValidateControlMesh(const ControlMesh& mesh);

// Writes ASCII OBJ (used by scenes and tests).
std::string WriteObj(const ControlMesh& mesh);

}  // namespace surfmap
