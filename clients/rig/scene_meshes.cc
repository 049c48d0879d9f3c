#include "clients/rig/scene_meshes.h"

#include <string>

#include "absl/strings/str_cat.h"
#include "server/mesh/primitive_meshes.h"

namespace surfmap {

std::vector<std::string_view> BuiltInSceneMeshNames() { return {"bottle", "plate"}; }

absl::StatusOr<ControlMesh> MakeBuiltInSceneMesh(std::string_view name) {
  // The bottle's level 0 is as coarse as keeps the shape, with body rings
  // spaced so that each sandpaper patch holds a control vertex: the planner
  // starts from 82 sites and refines only at the patches' edges.
  if (name == "bottle") {
    return MakeBottle(BottleShape{.segments = 8, .max_ring_spacing_mm = 32.0, .minimal_rings = true});
  }
  if (name == "plate") return MakeGridPlate(200.0, 150.0, 10, 8);
  return absl::NotFoundError(absl::StrCat("no built-in scene mesh '", std::string(name), "' (bottle, plate)"));
}

}  // namespace surfmap
