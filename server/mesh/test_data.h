// Test helper (header only, tests of this module): reads files of
// tests/data/meshes.
#pragma once

#include <fstream>
#include <sstream>
#include <string>

namespace surfmap {

// SURFMAP_SOURCE_DIR is defined for the test binary by this module's
// CMakeLists.txt, so tests run from any working directory.
inline std::string MeshTestDataPath(const std::string& name) {
  return std::string(SURFMAP_SOURCE_DIR) + "/tests/data/meshes/" + name;
}

// The file's bytes, or "" if it cannot be read (the test then fails on parse).
inline std::string ReadMeshTestData(const std::string& name) {
  std::ifstream in(MeshTestDataPath(name), std::ios::binary);
  std::ostringstream bytes;
  bytes << in.rdbuf();
  return bytes.str();
}

}  // namespace surfmap
