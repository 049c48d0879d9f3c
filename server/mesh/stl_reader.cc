#include "server/mesh/stl_reader.h"

#include <bit>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>
#include <unordered_map>
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "server/mesh/text_tokens.h"

namespace surfmap {
namespace {

constexpr std::size_t kHeaderBytes = 84;
constexpr std::size_t kTriangleBytes = 50;

// Merges corners with bit-identical coordinates.
class CornerIndex {
 public:
  int Add(const Eigen::Vector3d& p, ParsedMesh& out) {
    Key key{std::bit_cast<std::uint64_t>(p.x()), std::bit_cast<std::uint64_t>(p.y()),
            std::bit_cast<std::uint64_t>(p.z())};
    auto [it, inserted] = index_.try_emplace(key, static_cast<int>(out.mesh.positions.size()));
    if (inserted) out.mesh.positions.push_back(p);
    return it->second;
  }

 private:
  struct Key {
    std::uint64_t x, y, z;
    bool operator==(const Key&) const = default;
  };
  struct Hash {
    std::size_t operator()(const Key& k) const {
      return static_cast<std::size_t>(k.x * 0x9E3779B97F4A7C15ull ^ (k.y + 0x632BE59BD9B4E019ull) * 31 ^ k.z);
    }
  };
  std::unordered_map<Key, int, Hash> index_;
};

float ReadFloatLe(const char* p) {
  std::uint32_t bits;
  std::memcpy(&bits, p, 4);
  if constexpr (std::endian::native == std::endian::big) bits = __builtin_bswap32(bits);
  return std::bit_cast<float>(bits);
}

std::uint32_t ReadU32Le(const char* p) {
  std::uint32_t v;
  std::memcpy(&v, p, 4);
  if constexpr (std::endian::native == std::endian::big) v = __builtin_bswap32(v);
  return v;
}

absl::StatusOr<ParsedMesh> ReadBinary(std::string_view bytes, std::string_view source) {
  const std::uint32_t count = ReadU32Le(bytes.data() + 80);
  ParsedMesh out;
  // The size was checked against the count (IsBinaryStl): allocations are
  // bounded by the input.
  out.mesh.triangles.reserve(count);
  out.triangle_origin.reserve(count);
  CornerIndex corners;
  for (std::uint32_t t = 0; t < count; ++t) {
    const char* record = bytes.data() + kHeaderBytes + kTriangleBytes * t;
    std::vector<int> polygon(3);
    for (int c = 0; c < 3; ++c) {
      Eigen::Vector3d p;
      for (int i = 0; i < 3; ++i) p[i] = ReadFloatLe(record + 12 + 12 * c + 4 * i);
      if (!p.allFinite()) {
        return absl::InvalidArgumentError(absl::StrFormat(
            "%s: binary STL triangle %d (byte %d): corner %d has a non-finite coordinate", source, t,
            kHeaderBytes + kTriangleBytes * t, c));
      }
      polygon[c] = corners.Add(p, out);
    }
    AppendFanTriangles(polygon, absl::StrCat("STL triangle ", t), out);
  }
  return out;
}

absl::StatusOr<ParsedMesh> ReadAscii(std::string_view bytes, std::string_view source) {
  ParsedMesh out;
  CornerIndex corners;
  std::vector<int> facet;
  int facet_line = 0;
  int line_number = 0;
  bool in_facet = false, seen_solid = false, seen_end = false;
  std::size_t pos = 0;
  while (pos < bytes.size()) {
    std::size_t end = bytes.find('\n', pos);
    if (end == std::string_view::npos) end = bytes.size();
    const std::string_view line = bytes.substr(pos, end - pos);
    pos = end + 1;
    ++line_number;
    const std::vector<std::string_view> tokens = BlankSeparatedTokens(line);
    if (tokens.empty()) continue;
    auto error = [&](std::string_view what) {
      return absl::InvalidArgumentError(absl::StrFormat("%s line %d: %s", source, line_number, what));
    };
    if (seen_end) return error("data after endsolid");
    const std::string_view keyword = tokens[0];
    if (!seen_solid) {
      if (keyword != "solid") return error("an ASCII STL starts with 'solid'");
      seen_solid = true;
    } else if (keyword == "facet") {
      if (in_facet) return error("'facet' inside a facet (missing endfacet)");
      in_facet = true;
      facet.clear();
      facet_line = line_number;
    } else if (keyword == "outer" || keyword == "endloop") {
      if (!in_facet) return error(absl::StrFormat("'%s' outside a facet", keyword));
    } else if (keyword == "vertex") {
      if (!in_facet) return error("'vertex' outside a facet");
      if (tokens.size() != 4) return error(absl::StrFormat("vertex needs 3 coordinates, found %d", tokens.size() - 1));
      Eigen::Vector3d p;
      for (int i = 0; i < 3; ++i) {
        std::string_view token = tokens[i + 1];
        if (token.size() > 1 && token[0] == '+') token.remove_prefix(1);
        double value = 0.0;
        const auto [ptr, ec] = std::from_chars(token.data(), token.data() + token.size(), value);
        if (ec != std::errc() || ptr != token.data() + token.size() || !std::isfinite(value)) {
          return error(absl::StrFormat("vertex coordinate '%s' is not a finite number", tokens[i + 1]));
        }
        p[i] = value;
      }
      facet.push_back(corners.Add(p, out));
    } else if (keyword == "endfacet") {
      if (!in_facet) return error("'endfacet' without 'facet'");
      if (facet.size() != 3) return error(absl::StrFormat("facet (line %d) has %d vertices; STL facets have 3",
                                                          facet_line, facet.size()));
      AppendFanTriangles(facet, absl::StrCat("facet on line ", facet_line), out);
      in_facet = false;
    } else if (keyword == "endsolid") {
      if (in_facet) return error("'endsolid' inside a facet");
      seen_end = true;
    } else {
      return error(absl::StrFormat("unexpected '%s' in an ASCII STL", keyword));
    }
  }
  if (!seen_solid) return absl::InvalidArgumentError(absl::StrFormat("%s: empty STL", source));
  if (!seen_end) return absl::InvalidArgumentError(absl::StrFormat("%s: ASCII STL ends without 'endsolid'", source));
  return out;
}

}  // namespace

bool IsBinaryStl(std::string_view bytes) {
  if (bytes.size() < kHeaderBytes) return false;
  const std::uint64_t count = ReadU32Le(bytes.data() + 80);
  return bytes.size() == kHeaderBytes + kTriangleBytes * count;
}

absl::StatusOr<ParsedMesh> ReadStl(std::string_view bytes, std::string_view source) {
  if (IsBinaryStl(bytes)) return ReadBinary(bytes, source);
  if (bytes.substr(0, 5) == "solid") return ReadAscii(bytes, source);
  if (bytes.size() >= kHeaderBytes) {
    const std::uint64_t count = ReadU32Le(bytes.data() + 80);
    return absl::InvalidArgumentError(absl::StrFormat(
        "%s: binary STL says %d triangles (%d bytes) but has %d bytes (truncated or trailing data), and is not "
        "ASCII STL (no 'solid')",
        source, count, kHeaderBytes + kTriangleBytes * count, bytes.size()));
  }
  return absl::InvalidArgumentError(
      absl::StrFormat("%s: %d bytes: too short for a binary STL (84-byte header) and not ASCII STL", source,
                      bytes.size()));
}

}  // namespace surfmap
