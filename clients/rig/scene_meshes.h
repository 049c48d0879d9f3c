// The generators of the built-in scenes' control meshes (clients/scenes/*.obj
// are their output, written by surfmap-write-scene-meshes; a test checks the
// committed files still match).
#pragma once

#include <string_view>
#include <vector>

#include "absl/status/statusor.h"
#include "server/mesh/control_mesh.h"

namespace surfmap {

// The names of the built-in scene meshes: "bottle", "plate".
std::vector<std::string_view> BuiltInSceneMeshNames();

// bottle: a closed glass bottle standing on z = 0, body radius ~40 mm on the
//   Loop limit surface, 200 mm tall, body from z ~4 to 130 mm (MakeBottle
//   defaults: 12 segments, 360 faces).
// plate: an open flat plate in z = 0, 200 x 150 mm centred on the origin,
//   10 x 8 quads (160 triangles).
// NOT_FOUND for another name.
absl::StatusOr<ControlMesh> MakeBuiltInSceneMesh(std::string_view name);

}  // namespace surfmap
