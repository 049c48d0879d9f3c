#include "tests/fuzz/mesh_upload_check.h"

#include <bit>
#include <cmath>
#include <cstdint>
#include <memory>
#include <string>

#include "absl/strings/str_cat.h"
#include "server/mesh/loop_surface.h"
#include "tests/fuzz/fuzz_check.h"

namespace surfmap::fuzz {
namespace {

bool SameMesh(const ControlMesh& a, const ControlMesh& b) {
  if (a.positions.size() != b.positions.size() || a.triangles != b.triangles) return false;
  for (std::size_t v = 0; v < a.positions.size(); ++v) {
    for (int k = 0; k < 3; ++k) {
      if (std::bit_cast<std::uint64_t>(a.positions[v][k]) != std::bit_cast<std::uint64_t>(b.positions[v][k])) {
        return false;
      }
    }
  }
  return true;
}

void CheckRefinement(const ControlMesh& mesh) {
  const absl::StatusOr<std::unique_ptr<LoopSurface>> surface = LoopSurface::Create(mesh, 1);
  if (!surface.ok()) {
    FUZZ_CHECK(surface.status().code() == absl::StatusCode::kInvalidArgument,
               absl::StrCat("LoopSurface::Create on a validated mesh: ", Describe(surface.status())));
    return;
  }
  for (int k = 0; k <= 1; ++k) {
    const SurfaceLevel& level = (*surface)->level(k);
    FUZZ_CHECK(level.limit_positions.size() == level.positions.size() &&
                   level.limit_normals.size() == level.positions.size(),
               absl::StrCat("level ", k, ": per-vertex arrays differ in size"));
    for (std::size_t v = 0; v < level.positions.size(); ++v) {
      const std::string where = absl::StrCat("level ", k, " vertex ", v);
      FUZZ_CHECK(level.positions[v].allFinite() && level.limit_positions[v].allFinite(),
                 absl::StrCat(where, ": non-finite position"));
      FUZZ_CHECK(level.limit_normals[v].allFinite() && std::abs(level.limit_normals[v].norm() - 1.0) < 1e-6,
                 absl::StrCat(where, ": limit normal (", level.limit_normals[v].x(), ", ", level.limit_normals[v].y(),
                              ", ", level.limit_normals[v].z(), ") is not a unit vector"));
    }
  }
}

}  // namespace

void CheckMeshUpload(std::string_view bytes, MeshFormat format, std::string_view source) {
  const absl::StatusOr<ControlMesh> mesh = ParseControlMesh(bytes, format, source);
  if (!mesh.ok()) {
    FUZZ_CHECK(mesh.status().code() == absl::StatusCode::kInvalidArgument, Describe(mesh.status()));
    const std::string_view message(mesh.status().message().data(), mesh.status().message().size());
    FUZZ_CHECK(message.starts_with(source), Describe(mesh.status()));
    return;
  }
  const absl::Status valid = ValidateControlMesh(*mesh);
  FUZZ_CHECK(valid.ok(), absl::StrCat("ParseControlMesh accepted what ValidateControlMesh rejects: ", Describe(valid)));

  const std::string obj = WriteObj(*mesh);
  const absl::StatusOr<ControlMesh> reread = ParseControlMesh(obj, MeshFormat::kObj, "round trip");
  FUZZ_CHECK(reread.ok(), absl::StrCat("WriteObj output does not read back: ", Describe(reread.status())));
  FUZZ_CHECK(SameMesh(*mesh, *reread), "WriteObj -> ParseControlMesh changed the mesh");

  if (mesh->triangles.size() <= kMaxRefinedTriangles) CheckRefinement(*mesh);
}

}  // namespace surfmap::fuzz
