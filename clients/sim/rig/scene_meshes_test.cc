#include "clients/sim/rig/scene_meshes.h"

#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <utility>

#include <gtest/gtest.h>

namespace surfmap {
namespace {

// The committed OBJ files are the generator's output (a stale file fails here:
// rerun `surfmap-write-scene-meshes clients/sim/scenes`).
TEST(SceneMeshesTest, CommittedObjFilesMatchTheGenerator) {
  for (std::string_view name : BuiltInSceneMeshNames()) {
    const std::filesystem::path path =
        std::filesystem::path(SURFMAP_SOURCE_SCENES_DIR) / (std::string(name) + ".obj");
    std::ifstream in(path);
    ASSERT_TRUE(in) << path;
    std::stringstream bytes;
    bytes << in.rdbuf();
    auto committed = ParseControlMesh(bytes.str(), MeshFormat::kObj, path.string());
    ASSERT_TRUE(committed.ok()) << committed.status();
    auto generated = MakeBuiltInSceneMesh(name);
    ASSERT_TRUE(generated.ok()) << generated.status();
    ASSERT_EQ(committed->positions.size(), generated->positions.size()) << name;
    ASSERT_EQ(committed->triangles, generated->triangles) << name;
    for (size_t i = 0; i < committed->positions.size(); ++i) {
      EXPECT_NEAR((committed->positions[i] - generated->positions[i]).norm(), 0.0, 1e-9) << name << " v" << i;
    }
  }
}

TEST(SceneMeshesTest, OnlyThePlateIsOpen) {
  for (std::string_view name : BuiltInSceneMeshNames()) {
    const bool closed = name != "plate";
    auto mesh = MakeBuiltInSceneMesh(name);
    ASSERT_TRUE(mesh.ok());
    EXPECT_TRUE(ValidateControlMesh(*mesh).ok()) << name;
    EXPECT_GE(mesh->triangles.size(), 100u);
    EXPECT_LE(mesh->triangles.size(), 600u);
    std::map<std::pair<int, int>, int> edge_faces;
    for (const auto& t : mesh->triangles) {
      for (int k = 0; k < 3; ++k) {
        const int a = t[k], b = t[(k + 1) % 3];
        ++edge_faces[{std::min(a, b), std::max(a, b)}];
      }
    }
    int boundary = 0;
    for (const auto& [edge, count] : edge_faces) boundary += count == 1;
    EXPECT_EQ(boundary == 0, closed) << name << ": " << boundary << " boundary edges";
  }
  EXPECT_EQ(MakeBuiltInSceneMesh("teapot").status().code(), absl::StatusCode::kNotFound);
}

}  // namespace
}  // namespace surfmap
