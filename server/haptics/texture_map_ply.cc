#include "server/haptics/texture_map_ply.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <map>
#include <sstream>

#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"

namespace surfmap::haptics {
namespace {

void AppendDouble(std::string& out, double v) {
  if (std::isnan(v)) {
    out += "nan";
    return;
  }
  char buf[32];
  const int n = std::snprintf(buf, sizeof buf, "%.17g", v);
  out.append(buf, n);
}

// Grey 40..255 over [lo, hi] (Lloyd & Pai's Fig. 14: whiter = more friction).
void AppendGrey(std::string& out, double mu, double lo, double hi) {
  if (!std::isfinite(mu)) {
    out += " 170 60 150";  // magenta: unknown (as clients/render)
    return;
  }
  const double t = hi > lo ? std::clamp((mu - lo) / (hi - lo), 0.0, 1.0) : 0.5;
  const int g = static_cast<int>(std::lround(40 + t * 215));
  absl::StrAppend(&out, " ", g, " ", g, " ", g);
}

// (absl::string_view is not std::string_view in Debian's abseil: split and
// convert by hand.)
std::vector<std::string_view> SplitWords(std::string_view line) {
  std::vector<std::string_view> words;
  size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t' || line[i] == '\r')) ++i;
    const size_t start = i;
    while (i < line.size() && line[i] != ' ' && line[i] != '\t' && line[i] != '\r') ++i;
    if (i > start) words.push_back(line.substr(start, i - start));
  }
  return words;
}

template <typename T>
bool ToInt(std::string_view text, T* out) {
  return absl::SimpleAtoi(std::string(text), out);
}

}  // namespace

absl::StatusOr<std::string> WriteTexturePly(const TextureMap& map) {
  if (absl::Status s = ValidateTextureMap(map); !s.ok()) return s;
  const size_t n = map.positions.size();
  const bool normals = !map.normals.empty();
  const bool rough = !map.sigma.empty() && !map.a1.empty() && !map.a2.empty();
  std::string out = "ply\nformat ascii 1.0\n";
  absl::StrAppend(&out, "comment ", std::string(kTexturePlyFormat), "\n");
  absl::StrAppend(&out, "comment job_id ", map.job_id, "\n");
  absl::StrAppend(&out, "comment level ", map.level, "\n");
  out += "comment grid_step_mm ";
  AppendDouble(out, map.grid_step_mm);
  out += "\ncomment units mm N\n";
  absl::StrAppend(&out, "element vertex ", n, "\n");
  for (const char* p : {"x", "y", "z"}) absl::StrAppend(&out, "property double ", p, "\n");
  if (normals) {
    for (const char* p : {"nx", "ny", "nz"}) absl::StrAppend(&out, "property double ", p, "\n");
  }
  out += "property double mu\nproperty double mu_std\n";
  if (rough) out += "property double sigma\nproperty double a1\nproperty double a2\n";
  for (int j = 0; j < map.ar_order; ++j) absl::StrAppend(&out, "property double k", j + 1, "\n");
  if (!map.region.empty()) out += "property int region\n";
  if (!map.boundary_probability.empty()) out += "property double boundary_probability\n";
  out += "property uchar red\nproperty uchar green\nproperty uchar blue\n";
  absl::StrAppend(&out, "element face ", map.triangles.size(), "\n");
  out += "property list uchar int vertex_indices\nend_header\n";

  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (double mu : map.mu) {
    if (std::isfinite(mu)) {
      lo = std::min(lo, mu);
      hi = std::max(hi, mu);
    }
  }
  out.reserve(out.size() + n * 300);
  for (size_t v = 0; v < n; ++v) {
    auto field = [&](double value) {
      AppendDouble(out, value);
      out += ' ';
    };
    for (int a = 0; a < 3; ++a) field(map.positions[v][a]);
    if (normals) {
      for (int a = 0; a < 3; ++a) field(map.normals[v][a]);
    }
    field(map.mu[v]);
    field(map.mu_std[v]);
    if (rough) {
      field(map.sigma[v]);
      field(map.a1[v]);
      field(map.a2[v]);
    }
    for (int j = 0; j < map.ar_order; ++j) field(map.ReflectionAt(static_cast<int>(v), j));
    if (!map.region.empty()) absl::StrAppend(&out, map.region[v], " ");
    if (!map.boundary_probability.empty()) field(map.boundary_probability[v]);
    out.pop_back();
    AppendGrey(out, map.mu[v], lo, hi);
    out += '\n';
  }
  for (const auto& t : map.triangles) absl::StrAppend(&out, "3 ", t[0], " ", t[1], " ", t[2], "\n");
  return out;
}

absl::StatusOr<TextureMap> ReadTexturePly(std::string_view text, std::string_view source) {
  std::vector<std::string_view> lines;
  for (size_t start = 0; start <= text.size();) {
    const size_t end = std::min(text.find('\n', start), text.size());
    lines.push_back(text.substr(start, end - start));
    start = end + 1;
  }
  size_t line_no = 0;
  auto fail = [&](const std::string& what) {
    return absl::InvalidArgumentError(absl::StrCat(std::string(source), ":", line_no, ": ", what));
  };
  auto next = [&]() -> std::string_view {
    std::string_view l = line_no < lines.size() ? lines[line_no] : std::string_view();
    ++line_no;
    while (!l.empty() && (l.back() == ' ' || l.back() == '\r' || l.back() == '\t')) l.remove_suffix(1);
    return l;
  };
  if (next() != "ply") return fail("not a PLY file (first line is not 'ply')");
  if (next() != "format ascii 1.0") return fail("only 'format ascii 1.0' is read");
  TextureMap map;
  std::vector<std::string> vertex_props;
  size_t vertex_count = 0, face_count = 0;
  std::string element;
  bool face_list = false;
  for (;;) {
    if (line_no >= lines.size()) return fail("no end_header");
    std::vector<std::string_view> w = SplitWords(next());
    if (w.empty()) continue;
    if (w[0] == "end_header") break;
    if (w[0] == "comment" && w.size() == 3) {
      if (w[1] == "job_id" && !ToInt(w[2], &map.job_id)) return fail("bad job_id");
      if (w[1] == "level" && !ToInt(w[2], &map.level)) return fail("bad level");
      if (w[1] == "grid_step_mm" && !absl::SimpleAtod(std::string(w[2]), &map.grid_step_mm)) return fail("bad grid_step_mm");
      continue;
    }
    if (w[0] == "comment" || w[0] == "obj_info") continue;
    if (w[0] == "element" && w.size() == 3) {
      element = std::string(w[1]);
      size_t count = 0;
      if (!ToInt(w[2], &count)) return fail("bad element count");
      if (element == "vertex") vertex_count = count;
      else if (element == "face") face_count = count;
      else return fail(absl::StrCat("unexpected element '", element, "'"));
      continue;
    }
    if (w[0] == "property") {
      if (element == "vertex" && w.size() == 3) vertex_props.emplace_back(w[2]);
      else if (element == "face" && w.size() == 5 && w[1] == "list" && w[4] == "vertex_indices") face_list = true;
      else return fail("unexpected property line");
      continue;
    }
    return fail(absl::StrCat("unexpected header line '", std::string(w[0]), "'"));
  }
  if (face_count > 0 && !face_list) return fail("faces without a vertex_indices list");
  // The counts come from the file: bound them by the lines it actually has
  // (one per vertex, one per face) before anything is sized from them.
  const size_t lines_left = lines.size() - line_no;
  if (vertex_count > lines_left || face_count > lines_left - vertex_count) {
    return fail(absl::StrCat("header declares ", vertex_count, " vertices and ", face_count, " faces but only ",
                             lines_left, " lines follow it"));
  }
  std::map<std::string, int> column;
  for (size_t i = 0; i < vertex_props.size(); ++i) column[vertex_props[i]] = static_cast<int>(i);
  auto has = [&](const char* name) { return column.count(name) > 0; };
  for (const char* required : {"x", "y", "z", "mu", "mu_std"}) {
    if (!has(required)) return fail(absl::StrCat("no vertex property '", required, "'"));
  }
  int order = 0;
  while (has(absl::StrCat("k", order + 1).c_str())) ++order;
  map.ar_order = order;
  const bool normals = has("nx") && has("ny") && has("nz");
  const bool rough = has("sigma") && has("a1") && has("a2");
  map.positions.resize(vertex_count);
  if (normals) map.normals.resize(vertex_count);
  map.mu.resize(vertex_count);
  map.mu_std.resize(vertex_count);
  if (rough) {
    map.sigma.resize(vertex_count);
    map.a1.resize(vertex_count);
    map.a2.resize(vertex_count);
  }
  map.reflection.resize(vertex_count * order);
  if (has("region")) map.region.resize(vertex_count);
  if (has("boundary_probability")) map.boundary_probability.resize(vertex_count);
  std::vector<double> values(vertex_props.size());
  int max_region = -1;
  for (size_t v = 0; v < vertex_count; ++v) {
    std::vector<std::string_view> w = SplitWords(next());
    if (w.size() != vertex_props.size()) {
      return fail(absl::StrCat(w.size(), " fields for ", vertex_props.size(), " vertex properties"));
    }
    for (size_t i = 0; i < w.size(); ++i) {
      // strtod reads "nan"; the whole field must be a number.
      const std::string field(w[i]);
      char* end = nullptr;
      values[i] = std::strtod(field.c_str(), &end);
      if (end != field.c_str() + field.size()) return fail(absl::StrCat("'", field, "' is not a number"));
    }
    auto col = [&](const std::string& name) { return values[column.at(name)]; };
    map.positions[v] = {col("x"), col("y"), col("z")};
    if (normals) map.normals[v] = {col("nx"), col("ny"), col("nz")};
    map.mu[v] = col("mu");
    map.mu_std[v] = col("mu_std");
    if (rough) {
      map.sigma[v] = col("sigma");
      map.a1[v] = col("a1");
      map.a2[v] = col("a2");
    }
    for (int j = 0; j < order; ++j) map.reflection[v * order + j] = col(absl::StrCat("k", j + 1));
    if (!map.region.empty()) {
      const double r = col("region");
      if (r != std::floor(r)) return fail("region is not an integer");
      // -1 is unassigned; a vertex cannot be in more regions than there are
      // vertices, and the cast below is only defined for values an int holds.
      if (!(r >= -1 && r < static_cast<double>(vertex_count))) {
        return fail(absl::StrCat("region ", std::string(w[column.at("region")]), " is outside -1..", vertex_count - 1));
      }
      map.region[v] = static_cast<int>(r);
      max_region = std::max(max_region, map.region[v]);
    }
    if (!map.boundary_probability.empty()) map.boundary_probability[v] = col("boundary_probability");
  }
  map.triangles.resize(face_count);
  for (size_t f = 0; f < face_count; ++f) {
    std::vector<std::string_view> w = SplitWords(next());
    if (w.size() != 4 || w[0] != "3") return fail("faces must be triangles ('3 i j k')");
    for (int c = 0; c < 3; ++c) {
      if (!ToInt(w[c + 1], &map.triangles[f][c])) return fail("bad vertex index");
    }
  }
  // The PLY carries each vertex's region index, not the regions' models (see
  // the texture JSON): stand-in entries keep the indices valid.
  map.regions.resize(max_region + 1);
  for (int r = 0; r <= max_region; ++r) map.regions[r].region = r;
  if (absl::Status s = ValidateTextureMap(map); !s.ok()) return fail(std::string(s.message()));
  return map;
}

}  // namespace surfmap::haptics
