#include "server/mesh/obj_reader.h"

#include <charconv>
#include <cmath>
#include <cstdlib>
#include <string>
#include <vector>

#include <tiny_obj_loader.h>
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "server/mesh/text_tokens.h"

namespace surfmap {
namespace {

// Debian's tinyobjloader (1.0.x) stores a face's vertex count in an unsigned
// char: a larger polygon wraps around (1000 -> 232) and the cross-check
// below could only say the readers disagree. Such a face is refused here,
// naming its line and the limit.
constexpr int kMaxPolygonVertices = 255;

// What a first pass over the text learns that tinyobjloader does not report:
// coordinates parsed strictly (tinyobjloader turns "nan" or "abc" into 0 and
// silently drops faces with fewer than 3 vertices) and the line of each face.
struct ObjScan {
  std::vector<Eigen::Vector3d> positions;
  std::vector<int> face_lines;     // 1-based line of each `f` record, in order
  std::vector<int> face_sizes;     // vertex count of each `f` record
};

// Lines end where tinyobjloader ends them: at "\n", "\r\n" or a lone "\r"
// (classic Mac files), so that both passes see the same records and number
// them alike. Returns the line starting at `pos` and moves `pos` past its end.
std::string_view NextLine(std::string_view bytes, std::size_t& pos) {
  std::size_t end = bytes.find_first_of("\r\n", pos);
  if (end == std::string_view::npos) end = bytes.size();
  const std::string_view line = bytes.substr(pos, end - pos);
  pos = end + 1;
  if (end < bytes.size() && bytes[end] == '\r' && pos < bytes.size() && bytes[pos] == '\n') ++pos;
  return line;
}

absl::StatusOr<ObjScan> ScanObj(std::string_view bytes, std::string_view source) {
  ObjScan scan;
  int line_number = 0;
  std::size_t pos = 0;
  while (pos < bytes.size()) {
    const std::string_view line = NextLine(bytes, pos);
    ++line_number;
    // tinyobjloader reads each line as a C string, so a NUL would end the
    // line there for it but not for this scan: the two would count different
    // vertices or face corners.
    if (const std::size_t nul = line.find('\0'); nul != std::string_view::npos) {
      return absl::InvalidArgumentError(absl::StrFormat(
          "%s line %d: NUL byte at column %d (an OBJ file is text)", source, line_number, nul + 1));
    }
    const std::vector<std::string_view> tokens = BlankSeparatedTokens(line);
    if (tokens.empty()) continue;
    if (tokens[0] == "v") {
      if (tokens.size() < 4) {
        return absl::InvalidArgumentError(absl::StrFormat("%s line %d: vertex needs 3 coordinates, found %d",
                                                          source, line_number, tokens.size() - 1));
      }
      Eigen::Vector3d p;
      for (int i = 0; i < 3; ++i) {
        const std::string_view token = tokens[i + 1];
        // from_chars rejects a leading '+', which OBJ writers may emit.
        const std::string_view digits = token.substr(token.size() > 1 && token[0] == '+' ? 1 : 0);
        double value = 0.0;
        const auto [ptr, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), value);
        if (ec == std::errc::result_out_of_range) {
          // 1e400 becomes inf (rejected below), 1e-400 becomes 0.
          value = std::strtod(std::string(digits).c_str(), nullptr);
        } else if (ec != std::errc() || ptr != digits.data() + digits.size()) {
          return absl::InvalidArgumentError(
              absl::StrFormat("%s line %d: vertex coordinate '%s' is not a number", source, line_number, token));
        }
        if (!std::isfinite(value)) {
          return absl::InvalidArgumentError(absl::StrFormat(
              "%s line %d: vertex coordinate '%s' is not finite (NaN/inf)", source, line_number, token));
        }
        p[i] = value;
      }
      scan.positions.push_back(p);
    } else if (tokens[0] == "f") {
      if (tokens.size() < 4) {
        return absl::InvalidArgumentError(absl::StrFormat(
            "%s line %d: face has %d vertices; a face needs at least 3", source, line_number, tokens.size() - 1));
      }
      if (tokens.size() - 1 > kMaxPolygonVertices) {
        return absl::InvalidArgumentError(absl::StrFormat(
            "%s line %d: a face with %d vertices; the limit is %d vertices per polygon (split it into smaller "
            "polygons or triangles)", source, line_number, tokens.size() - 1, kMaxPolygonVertices));
      }
      scan.face_lines.push_back(line_number);
      scan.face_sizes.push_back(static_cast<int>(tokens.size()) - 1);
    }
  }
  return scan;
}

}  // namespace

absl::StatusOr<ParsedMesh> ReadObj(std::string_view bytes, std::string_view source) {
  absl::StatusOr<ObjScan> scan = ScanObj(bytes, source);
  if (!scan.ok()) return scan.status();

  tinyobj::ObjReaderConfig config;
  config.triangulate = false;  // we fan-triangulate ourselves, keeping polygon provenance
  config.vertex_color = false;
  tinyobj::ObjReader reader;
  if (!reader.ParseFromString(std::string(bytes), std::string(), config)) {
    std::string message = reader.Error();
    while (!message.empty() && (message.back() == '\n' || message.back() == '.')) message.pop_back();
    return absl::InvalidArgumentError(absl::StrFormat("%s: OBJ parse error: %s", source, message));
  }

  const std::size_t num_vertices = reader.GetAttrib().vertices.size() / 3;
  if (num_vertices != scan->positions.size()) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "%s: OBJ reader found %d vertices where the text has %d `v` records", source, num_vertices,
        scan->positions.size()));
  }

  ParsedMesh out;
  out.mesh.positions = std::move(scan->positions);
  std::size_t face = 0;
  std::vector<int> polygon;
  for (const tinyobj::shape_t& shape : reader.GetShapes()) {
    std::size_t offset = 0;
    for (const unsigned int size : shape.mesh.num_face_vertices) {
      // tinyobjloader keeps `f` records in file order; cross-check so the
      // line numbers we report are the right ones.
      if (face >= scan->face_lines.size() || scan->face_sizes[face] != static_cast<int>(size)) {
        return absl::InternalError(absl::StrFormat(
            "%s: OBJ face %d does not match the text's `f` records (reader disagreement)", source, face));
      }
      const int line = scan->face_lines[face];
      polygon.clear();
      for (unsigned int k = 0; k < size; ++k) {
        const int index = shape.mesh.indices[offset + k].vertex_index;
        if (index < 0 || static_cast<std::size_t>(index) >= num_vertices) {
          // tinyobjloader resolves negative (relative) indices; report 1-based.
          return absl::InvalidArgumentError(absl::StrFormat(
              "%s line %d: face vertex index %d is out of range (the file has %d vertices, indices are 1..%d)",
              source, line, index + 1, num_vertices, num_vertices));
        }
        polygon.push_back(index);
      }
      offset += size;
      AppendFanTriangles(polygon, absl::StrCat("face on line ", line), out);
      ++face;
    }
  }
  if (face != scan->face_lines.size()) {
    return absl::InternalError(absl::StrFormat("%s: OBJ reader returned %d faces where the text has %d", source,
                                               face, scan->face_lines.size()));
  }
  return out;
}

}  // namespace surfmap
