#include "clients/rig/scene_meshes.h"

#include <string>

#include "absl/strings/str_cat.h"
#include "server/mesh/primitive_meshes.h"

namespace surfmap {

std::vector<std::string_view> BuiltInSceneMeshNames() { return {"bottle", "plate"}; }

absl::StatusOr<ControlMesh> MakeBuiltInSceneMesh(std::string_view name) {
  if (name == "bottle") return MakeBottle(BottleShape{});
  if (name == "plate") return MakeGridPlate(200.0, 150.0, 10, 8);
  return absl::NotFoundError(absl::StrCat("no built-in scene mesh '", std::string(name), "' (bottle, plate)"));
}

}  // namespace surfmap
