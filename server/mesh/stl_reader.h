// Internal to the mesh module: STL (ASCII and binary) -> ParsedMesh, a small
// strict reader. STL stores every triangle with its own three corners; corners
// with bit-identical coordinates are merged into one vertex here (that is the
// format's way of sharing vertices, not a repair). Near-identical corners are
// left to the upload's repair (weld within a tolerance, reported).
#pragma once

#include <string_view>

#include "absl/status/statusor.h"
#include "server/mesh/parsed_mesh.h"

namespace surfmap {

// True when `bytes` has the size of a binary STL: 84 + 50 x the triangle
// count in its header (how binary files whose header begins "solid" are told
// apart from ASCII ones).
bool IsBinaryStl(std::string_view bytes);

// Binary: 80-byte header, uint32 triangle count (little endian), 50 bytes per
// triangle (normal, 3 corners as float32, uint16 attribute); the size must be
// exact. ASCII: solid / facet normal / outer loop / 3 x vertex / endloop /
// endfacet ... endsolid. The facet normals are ignored (the winding,
// counter-clockwise seen from outside, is the orientation). Errors name
// `source` and the triangle (binary) or line (ASCII): truncated or trailing
// data, unparsable or non-finite coordinates, a facet without 3 vertices.
// Does not run the topology checks.
absl::StatusOr<ParsedMesh> ReadStl(std::string_view bytes, std::string_view source);

}  // namespace surfmap
