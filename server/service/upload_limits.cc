#include "server/service/upload_limits.h"

#include "absl/strings/str_cat.h"

namespace surfmap {
namespace {

bool IsSpace(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f'; }

}  // namespace

absl::Status CheckObjPolygonSizes(std::string_view text) {
  int line_number = 0;
  size_t start = 0;
  while (start < text.size()) {
    size_t end = text.find('\n', start);
    if (end == std::string_view::npos) end = text.size();
    std::string_view line = text.substr(start, end - start);
    start = end + 1;
    ++line_number;
    size_t i = 0;
    while (i < line.size() && IsSpace(line[i])) ++i;
    if (i + 1 >= line.size() || line[i] != 'f' || !IsSpace(line[i + 1])) continue;
    int vertices = 0;
    bool in_token = false;
    for (size_t k = i + 1; k < line.size() && line[k] != '#'; ++k) {
      const bool space = IsSpace(line[k]);
      if (!space && !in_token) ++vertices;
      in_token = !space;
    }
    if (vertices > kMaxObjPolygonVertices) {
      return absl::InvalidArgumentError(absl::StrCat(
          "OBJ line ", line_number, ": a face with ", vertices, " vertices; the limit is ", kMaxObjPolygonVertices,
          " vertices per polygon (split it into smaller polygons or triangles)"));
    }
  }
  return absl::OkStatus();
}

}  // namespace surfmap
