// Limits on an uploaded mesh that are checked before any reader sees it.
#pragma once

#include <string_view>

#include "absl/status/status.h"

namespace surfmap {

// Debian's tinyobjloader (1.0.x) stores a face's vertex count in an unsigned
// char: a larger polygon wraps around (1000 -> 232) and the OBJ reader's
// cross-check can only say the readers disagree. A polygon of more vertices
// is refused up front, naming its line and the limit.
inline constexpr int kMaxObjPolygonVertices = 255;

// INVALID_ARGUMENT for the first `f` record with more than
// kMaxObjPolygonVertices vertices. One pass, no allocation.
absl::Status CheckObjPolygonSizes(std::string_view obj_text);

}  // namespace surfmap
