// The generators of the built-in scenes' control meshes (clients/sim/scenes/*.obj
// are their output, written by surfmap-write-scene-meshes; a test checks the
// committed files still match).
#pragma once

#include <string_view>
#include <vector>

#include "absl/status/statusor.h"
#include "server/mesh/control_mesh.h"

namespace surfmap {

// The names of the built-in scene meshes: "bottle", "plate", "banded_vase",
// "strip_block", "dotted_egg", "torus_handle".
std::vector<std::string_view> BuiltInSceneMeshNames();

// bottle: a closed glass bottle standing on z = 0, body radius ~40 mm on the
//   Loop limit surface, 200 mm tall, body from z ~4 to 130 mm (MakeBottle with
//   8 segments and minimal rings: 82 vertices, 160 faces; its rings are
//   spaced so that each sandpaper patch holds a control vertex).
// plate: an open flat plate in z = 0, 200 x 150 mm centred on the origin,
//   10 x 8 quads (160 triangles).
// The four below are meshes of the kind a lab brings (a remeshed scan), not
// built around their scenes' regions:
// banded_vase: a closed vase of revolution standing on z = 0, ~160 mm tall,
//   radius ~25-43 mm, 11 segments and 10 rings at uneven heights (112
//   vertices, 220 faces).
// strip_block: a closed rounded block (superellipsoid |x/70|^4 + |y/45|^4 +
//   |z/30|^4 = 1) meshed from a turned icosphere (162 vertices, 320 faces).
// dotted_egg: a closed ellipsoid with radii 46, 40, 60 mm meshed from a turned
//   icosphere (162 vertices, 320 faces).
// torus_handle: a closed torus about z, major radius 45 mm, tube radius
//   ~15 mm on the limit surface, 18 x 9 vertices turned off the axes (162
//   vertices, 324 faces): strongly curved everywhere (a 20 mm drag turns 80
//   degrees around the tube).
// NOT_FOUND for another name.
absl::StatusOr<ControlMesh> MakeBuiltInSceneMesh(std::string_view name);

}  // namespace surfmap
