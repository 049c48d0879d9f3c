#include "server/mesh/control_mesh.h"

#include <charconv>
#include <string>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_join.h"
#include "server/mesh/obj_reader.h"
#include "server/mesh/parsed_mesh.h"
#include "server/mesh/ply_reader.h"
#include "server/mesh/stl_reader.h"

namespace surfmap {

absl::StatusOr<ControlMesh> ParseControlMesh(std::string_view bytes, MeshFormat format, std::string_view source) {
  absl::StatusOr<ParsedMesh> parsed =
      format == MeshFormat::kPly   ? ReadPly(bytes, source)
      : format == MeshFormat::kStl ? ReadStl(bytes, source)
                                   : ReadObj(bytes, source);
  if (!parsed.ok()) return parsed.status();
  // Strict: a repeat is a defect that only an upload (ParseAndRepairMesh) repairs.
  if (parsed->polygons_with_repeated_vertex > 0) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "%s: triangle %d (%s) repeats a vertex index (%s)", source, parsed->first_repeated_vertex_triangle,
        parsed->first_repeated_vertex_polygon, absl::StrJoin(parsed->first_repeated_vertex_indices, ", ")));
  }
  const absl::Status valid = ValidateTriangleMesh(parsed->mesh, [&](int t) {
    return absl::StrCat("triangle ", t, " (", parsed->triangle_origin[t], ")");
  });
  if (!valid.ok()) return absl::InvalidArgumentError(absl::StrFormat("%s: %s", source, valid.message()));
  return std::move(parsed->mesh);
}

absl::StatusOr<ControlMesh> ParseControlMeshAuto(std::string_view bytes, std::string_view source) {
  return ParseControlMesh(bytes, GuessMeshFormat(bytes), source);
}

MeshFormat GuessMeshFormat(std::string_view bytes) {
  // "ply" followed by a line end is the PLY magic; a binary STL's size is
  // exactly 84 + 50 x its triangle count; "solid" starts an ASCII STL (and,
  // against the standard, some binary headers, which the size test catches
  // first); everything else is taken as OBJ.
  if (bytes.substr(0, 4) == "ply\n" || bytes.substr(0, 5) == "ply\r\n") return MeshFormat::kPly;
  if (IsBinaryStl(bytes)) return MeshFormat::kStl;
  if (bytes.substr(0, 5) == "solid") return MeshFormat::kStl;
  return MeshFormat::kObj;
}

absl::Status ValidateControlMesh(const ControlMesh& mesh) {
  return ValidateTriangleMesh(mesh, [](int t) { return absl::StrCat("triangle ", t); });
}

std::string WriteObj(const ControlMesh& mesh) {
  std::string out;
  out.reserve(mesh.positions.size() * 48 + mesh.triangles.size() * 24);
  absl::StrAppend(&out, "# surfmap control mesh: ", mesh.positions.size(), " vertices, ", mesh.triangles.size(),
                  " triangles, mm\n");
  for (const Eigen::Vector3d& p : mesh.positions) {
    out += 'v';
    for (int i = 0; i < 3; ++i) {
      // Shortest text that reads back to the same double.
      char buffer[32];
      const auto result = std::to_chars(buffer, buffer + sizeof(buffer), p[i]);
      out += ' ';
      out.append(buffer, result.ptr);
    }
    out += '\n';
  }
  for (const auto& t : mesh.triangles) {
    absl::StrAppendFormat(&out, "f %d %d %d\n", t[0] + 1, t[1] + 1, t[2] + 1);
  }
  return out;
}

}  // namespace surfmap
