// What the mesh harnesses (OBJ and PLY) check: the object upload path of the
// server (ParseControlMesh, then LoopSurface::Create at level 1, as
// JobCoordinator does before it stores an object).
#pragma once

#include <string_view>

#include "server/mesh/control_mesh.h"

namespace surfmap::fuzz {

// Meshes with more triangles than this are parsed and validated but not
// refined: refinement costs ~10 us per triangle under the sanitizers and a
// larger mesh reaches no new code.
inline constexpr std::size_t kMaxRefinedTriangles = 2000;

// Parses `bytes` as `format` and checks, beyond the sanitizers:
// - a rejection is INVALID_ARGUMENT and its message starts with `source`
//   (ParseControlMesh's contract; INTERNAL would be a 500 for a bad upload);
// - an accepted mesh passes ValidateControlMesh and survives WriteObj ->
//   ParseControlMesh(OBJ) exactly (positions bit for bit, same triangles);
// - a small accepted mesh refines to level 1 or is rejected with
//   INVALID_ARGUMENT, and a refined surface has finite positions and unit
//   limit normals.
void CheckMeshUpload(std::string_view bytes, MeshFormat format, std::string_view source);

}  // namespace surfmap::fuzz
