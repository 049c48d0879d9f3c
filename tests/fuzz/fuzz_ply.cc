// libFuzzer harness: PLY bytes -> ParseControlMesh -> LoopSurface level 1, the
// object upload path (checks in mesh_upload_check.h).
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "tests/fuzz/mesh_upload_check.h"

namespace {

// The seed meshes are at most 12 KB; a longer text only repeats records.
constexpr std::size_t kMaxInputBytes = 64 * 1024;

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size > kMaxInputBytes) return -1;  // -1: not added to the corpus
  surfmap::fuzz::CheckMeshUpload(std::string_view(reinterpret_cast<const char*>(data), size),
                                 surfmap::MeshFormat::kPly, "fuzz.ply");
  return 0;
}
