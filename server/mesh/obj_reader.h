// Internal to the mesh module: Wavefront OBJ -> ParsedMesh (tinyobjloader).
#pragma once

#include <string_view>

#include "absl/status/statusor.h"
#include "server/mesh/parsed_mesh.h"

namespace surfmap {

// Reads `v` and `f` records (other records are ignored; `l`/`p` elements are
// not surface). Polygons are fan-triangulated. Errors name `source` and the
// line: unparsable or non-finite coordinates, faces with fewer than 3 or
// more than 255 vertices, out-of-range indices. Does not run the topology checks.
absl::StatusOr<ParsedMesh> ReadObj(std::string_view bytes, std::string_view source);

}  // namespace surfmap
