// surfmap-export-scene-texture SCENE OUT_PREFIX [--level K]: writes a scene's
// truth as a texture map in every export format (OUT_PREFIX.ply, .gltf,
// .glb, .texture.json). For the glTF validator test and for trying the
// exports in MeshLab/Blender without a server.
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include <CLI/CLI.hpp>
#include "clients/haptics/scene/scene_texture_map.h"
#include "server/haptics/texture_map_gltf.h"
#include "server/haptics/texture_map_ply.h"
#include "server/haptics/texture_model_json.h"

namespace {

bool Write(const std::string& path, const std::string& bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  out.close();
  if (!out) std::fprintf(stderr, "%s: cannot write\n", path.c_str());
  return static_cast<bool>(out);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Write a scene's true texture map as PLY, glTF, GLB and texture JSON"};
  std::string scene_name, prefix;
  int level = 2;
  app.add_option("scene", scene_name, "Scene name (clients/sim/scenes)")->required();
  app.add_option("out_prefix", prefix, "Output path prefix")->required();
  app.add_option("--level", level, "Loop subdivision level of the mesh")->check(CLI::Range(0, 5))->capture_default_str();
  CLI11_PARSE(app, argc, argv);
  using namespace surfmap;
  absl::StatusOr<Scene> scene = LoadSceneByName(scene_name);
  if (!scene.ok()) {
    std::fprintf(stderr, "%s\n", std::string(scene.status().message()).c_str());
    return 1;
  }
  absl::StatusOr<std::unique_ptr<LoopSurface>> surface = LoopSurface::Create(scene->mesh, level);
  if (!surface.ok()) {
    std::fprintf(stderr, "%s\n", std::string(surface.status().message()).c_str());
    return 1;
  }
  std::error_code ec;
  const std::filesystem::path parent = std::filesystem::path(prefix).parent_path();
  if (!parent.empty()) std::filesystem::create_directories(parent, ec);
  const haptics::TextureMap map = haptics::SceneTruthTextureMap(*scene, **surface, level);
  absl::StatusOr<std::string> ply = haptics::WriteTexturePly(map);
  absl::StatusOr<std::string> gltf = haptics::WriteTextureGltf(map, false);
  absl::StatusOr<std::string> glb = haptics::WriteTextureGltf(map, true);
  absl::StatusOr<nlohmann::json> json = haptics::TextureModelToJson(map);
  for (const absl::Status& s : {ply.status(), gltf.status(), glb.status(), json.status()}) {
    if (!s.ok()) {
      std::fprintf(stderr, "%s\n", std::string(s.message()).c_str());
      return 1;
    }
  }
  const bool ok = Write(prefix + ".ply", *ply) && Write(prefix + ".gltf", *gltf) && Write(prefix + ".glb", *glb) &&
                  Write(prefix + ".texture.json", json->dump(1) + "\n");
  if (ok) std::printf("%s.{ply,gltf,glb,texture.json}: %d vertices, %zu triangles\n", prefix.c_str(),
                      map.vertex_count(), map.triangles.size());
  return ok ? 0 : 1;
}
