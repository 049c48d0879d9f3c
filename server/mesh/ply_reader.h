// Internal to the mesh module: Stanford PLY -> ParsedMesh, a small strict
// reader (ASCII, binary_little_endian, binary_big_endian, version 1.0).
#pragma once

#include <string_view>

#include "absl/status/statusor.h"
#include "server/mesh/parsed_mesh.h"

namespace surfmap {

// Requires element `vertex` with float/double properties x, y, z and element
// `face` with an integer list property `vertex_indices` (or `vertex_index`).
// Every other element and property (lists included) is skipped by its
// declared type. Errors name `source` and the header line, data line (ASCII)
// or element instance and byte offset (binary): bad header, unsupported
// types, wrong token counts, truncated data, trailing data, non-finite
// coordinates, out-of-range indices. Does not run the topology checks.
absl::StatusOr<ParsedMesh> ReadPly(std::string_view bytes, std::string_view source);

}  // namespace surfmap
