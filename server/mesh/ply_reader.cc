#include "server/mesh/ply_reader.h"

#include <bit>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "server/base/status_macros.h"

namespace surfmap {
namespace {

// Guards against headers that promise absurd sizes.
constexpr std::uint64_t kMaxElementCount = std::numeric_limits<std::int32_t>::max();
constexpr double kMaxPolygonSize = 1 << 16;

enum class PlyType { kInt8, kUint8, kInt16, kUint16, kInt32, kUint32, kFloat32, kFloat64 };

std::optional<PlyType> ParseType(std::string_view name) {
  if (name == "char" || name == "int8") return PlyType::kInt8;
  if (name == "uchar" || name == "uint8") return PlyType::kUint8;
  if (name == "short" || name == "int16") return PlyType::kInt16;
  if (name == "ushort" || name == "uint16") return PlyType::kUint16;
  if (name == "int" || name == "int32") return PlyType::kInt32;
  if (name == "uint" || name == "uint32") return PlyType::kUint32;
  if (name == "float" || name == "float32") return PlyType::kFloat32;
  if (name == "double" || name == "float64") return PlyType::kFloat64;
  return std::nullopt;
}

bool IsInteger(PlyType t) { return t != PlyType::kFloat32 && t != PlyType::kFloat64; }

std::size_t SizeOf(PlyType t) {
  switch (t) {
    case PlyType::kInt8:
    case PlyType::kUint8: return 1;
    case PlyType::kInt16:
    case PlyType::kUint16: return 2;
    case PlyType::kInt32:
    case PlyType::kUint32:
    case PlyType::kFloat32: return 4;
    case PlyType::kFloat64: return 8;
  }
  return 0;
}

struct PlyProperty {
  std::string name;
  PlyType type = PlyType::kFloat32;  // item type for lists
  bool is_list = false;
  PlyType count_type = PlyType::kUint8;
};

struct PlyElement {
  std::string name;
  std::uint64_t count = 0;
  int header_line = 0;
  std::vector<PlyProperty> properties;
};

enum class PlyEncoding { kAscii, kBinaryLittleEndian, kBinaryBigEndian };

struct PlyHeader {
  PlyEncoding encoding = PlyEncoding::kAscii;
  std::vector<PlyElement> elements;
  std::size_t data_offset = 0;  // first byte after "end_header\n"
  int data_first_line = 0;      // line number of the first data line (ASCII)
};

std::vector<std::string_view> SplitBlanks(std::string_view line) {
  std::vector<std::string_view> out;
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t' || line[i] == '\r')) ++i;
    std::size_t j = i;
    while (j < line.size() && line[j] != ' ' && line[j] != '\t' && line[j] != '\r') ++j;
    if (j > i) out.push_back(line.substr(i, j - i));
    i = j;
  }
  return out;
}

absl::StatusOr<PlyHeader> ParseHeader(std::string_view bytes, std::string_view source) {
  PlyHeader header;
  std::size_t pos = 0;
  int line_number = 0;
  bool have_format = false;
  auto error = [&](std::string_view what) {
    return absl::InvalidArgumentError(absl::StrFormat("%s: PLY header line %d: %s", source, line_number, what));
  };
  while (true) {
    if (pos >= bytes.size()) {
      return absl::InvalidArgumentError(absl::StrFormat("%s: PLY header has no end_header line", source));
    }
    std::size_t end = bytes.find('\n', pos);
    if (end == std::string_view::npos) {
      return absl::InvalidArgumentError(absl::StrFormat("%s: PLY header has no end_header line", source));
    }
    std::string_view line = bytes.substr(pos, end - pos);
    pos = end + 1;
    ++line_number;
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    const std::vector<std::string_view> tokens = SplitBlanks(line);
    if (line_number == 1) {
      if (line != "ply") return error("the file must start with the line 'ply'");
      continue;
    }
    if (tokens.empty()) return error("empty line in the header");
    const std::string_view keyword = tokens[0];
    if (keyword == "comment" || keyword == "obj_info") continue;
    if (keyword == "format") {
      if (have_format) return error("second format line");
      if (tokens.size() != 3) return error("expected 'format <ascii|binary_little_endian|binary_big_endian> 1.0'");
      if (tokens[1] == "ascii") {
        header.encoding = PlyEncoding::kAscii;
      } else if (tokens[1] == "binary_little_endian") {
        header.encoding = PlyEncoding::kBinaryLittleEndian;
      } else if (tokens[1] == "binary_big_endian") {
        header.encoding = PlyEncoding::kBinaryBigEndian;
      } else {
        return error(absl::StrFormat("unknown format '%s'", tokens[1]));
      }
      if (tokens[2] != "1.0") return error(absl::StrFormat("unsupported PLY version '%s' (need 1.0)", tokens[2]));
      have_format = true;
    } else if (keyword == "element") {
      if (!have_format) return error("element before the format line");
      if (tokens.size() != 3) return error("expected 'element <name> <count>'");
      PlyElement element;
      element.name = std::string(tokens[1]);
      element.header_line = line_number;
      const auto [ptr, ec] =
          std::from_chars(tokens[2].data(), tokens[2].data() + tokens[2].size(), element.count);
      if (ec != std::errc() || ptr != tokens[2].data() + tokens[2].size() || element.count > kMaxElementCount) {
        return error(absl::StrFormat("bad element count '%s'", tokens[2]));
      }
      for (const PlyElement& other : header.elements) {
        if (other.name == element.name) return error(absl::StrCat("element '", element.name, "' declared twice"));
      }
      header.elements.push_back(std::move(element));
    } else if (keyword == "property") {
      if (header.elements.empty()) return error("property before any element");
      PlyProperty property;
      if (tokens.size() >= 2 && tokens[1] == "list") {
        if (tokens.size() != 5) return error("expected 'property list <count type> <item type> <name>'");
        const std::optional<PlyType> count_type = ParseType(tokens[2]);
        const std::optional<PlyType> item_type = ParseType(tokens[3]);
        if (!count_type || !item_type) {
          return error(absl::StrFormat("unknown type in 'property list %s %s'", tokens[2], tokens[3]));
        }
        if (!IsInteger(*count_type)) return error("a list count type must be an integer type");
        property.is_list = true;
        property.count_type = *count_type;
        property.type = *item_type;
        property.name = std::string(tokens[4]);
      } else {
        if (tokens.size() != 3) return error("expected 'property <type> <name>'");
        const std::optional<PlyType> type = ParseType(tokens[1]);
        if (!type) return error(absl::StrFormat("unknown property type '%s'", tokens[1]));
        property.type = *type;
        property.name = std::string(tokens[2]);
      }
      for (const PlyProperty& other : header.elements.back().properties) {
        if (other.name == property.name) {
          return error(absl::StrCat("property '", property.name, "' declared twice"));
        }
      }
      header.elements.back().properties.push_back(std::move(property));
    } else if (keyword == "end_header") {
      if (tokens.size() != 1) return error("junk after end_header");
      break;
    } else {
      return error(absl::StrFormat("unknown header keyword '%s'", keyword));
    }
  }
  if (!have_format) return absl::InvalidArgumentError(absl::StrFormat("%s: PLY header has no format line", source));
  for (const PlyElement& element : header.elements) {
    if (element.properties.empty() && element.count > 0) {
      return absl::InvalidArgumentError(absl::StrFormat("%s: PLY header line %d: element '%s' has no properties",
                                                        source, element.header_line, element.name));
    }
  }
  header.data_offset = pos;
  header.data_first_line = line_number + 1;
  return header;
}

// Data sources: one element instance at a time. ASCII puts each instance on
// its own line; binary packs them back to back.
class AsciiSource {
 public:
  AsciiSource(std::string_view data, int first_line, std::string_view source)
      : data_(data), line_number_(first_line - 1), source_(source) {}

  absl::Status BeginInstance(const std::string& element, std::uint64_t index) {
    element_ = element;
    index_ = index;
    while (true) {
      if (pos_ >= data_.size()) {
        return absl::InvalidArgumentError(absl::StrFormat(
            "%s: PLY data ends before %s %d (file truncated or header count too large)", source_, element, index));
      }
      std::size_t end = data_.find('\n', pos_);
      if (end == std::string_view::npos) end = data_.size();
      const std::string_view line = data_.substr(pos_, end - pos_);
      pos_ = end + 1;
      ++line_number_;
      tokens_ = SplitBlanks(line);
      next_ = 0;
      if (!tokens_.empty()) return absl::OkStatus();
    }
  }

  absl::Status Read(PlyType type, double* value) {
    if (next_ >= tokens_.size()) {
      return absl::InvalidArgumentError(absl::StrFormat("%s: PLY line %d (%s %d): too few values (%d)", source_,
                                                        line_number_, element_, index_, tokens_.size()));
    }
    const std::string_view token = tokens_[next_++];
    const char* begin = token.data();
    const char* end = token.data() + token.size();
    if (IsInteger(type)) {
      std::int64_t integer = 0;
      if (begin != end && *begin == '+') ++begin;
      const auto [ptr, ec] = std::from_chars(begin, end, integer);
      if (ec != std::errc() || ptr != end) return BadToken(token, "an integer");
      *value = static_cast<double>(integer);
      const bool fits = [&] {
        switch (type) {
          case PlyType::kInt8: return integer >= -128 && integer <= 127;
          case PlyType::kUint8: return integer >= 0 && integer <= 255;
          case PlyType::kInt16: return integer >= -32768 && integer <= 32767;
          case PlyType::kUint16: return integer >= 0 && integer <= 65535;
          case PlyType::kInt32: return integer >= INT32_MIN && integer <= INT32_MAX;
          case PlyType::kUint32: return integer >= 0 && integer <= UINT32_MAX;
          default: return true;
        }
      }();
      if (!fits) return BadToken(token, "a value in range of its declared type");
      return absl::OkStatus();
    }
    if (begin != end && *begin == '+') ++begin;
    const auto [ptr, ec] = std::from_chars(begin, end, *value);
    if (ec == std::errc::result_out_of_range) {
      *value = std::strtod(std::string(begin, end).c_str(), nullptr);  // inf or 0
    } else if (ec != std::errc() || ptr != end) {
      return BadToken(token, "a number");
    }
    return absl::OkStatus();
  }

  absl::Status EndInstance() {
    if (next_ != tokens_.size()) {
      return absl::InvalidArgumentError(absl::StrFormat("%s: PLY line %d (%s %d): %d values, expected %d", source_,
                                                        line_number_, element_, index_, tokens_.size(), next_));
    }
    return absl::OkStatus();
  }

  absl::Status Finish() {
    while (pos_ < data_.size()) {
      std::size_t end = data_.find('\n', pos_);
      if (end == std::string_view::npos) end = data_.size();
      const std::string_view line = data_.substr(pos_, end - pos_);
      pos_ = end + 1;
      ++line_number_;
      if (!SplitBlanks(line).empty()) {
        return absl::InvalidArgumentError(absl::StrFormat(
            "%s: PLY line %d: data after the last declared element", source_, line_number_));
      }
    }
    return absl::OkStatus();
  }

  std::string Where() const { return absl::StrFormat("PLY line %d (%s %d)", line_number_, element_, index_); }

 private:
  absl::Status BadToken(std::string_view token, std::string_view expected) const {
    return absl::InvalidArgumentError(absl::StrFormat("%s: PLY line %d (%s %d): '%s' is not %s", source_,
                                                      line_number_, element_, index_, token, expected));
  }

  std::string_view data_;
  std::size_t pos_ = 0;
  int line_number_;
  std::string_view source_;
  std::vector<std::string_view> tokens_;
  std::size_t next_ = 0;
  std::string element_;
  std::uint64_t index_ = 0;
};

class BinarySource {
 public:
  BinarySource(std::string_view data, std::size_t header_size, bool big_endian, std::string_view source)
      : data_(data), pos_(header_size), big_endian_(big_endian), source_(source) {}

  absl::Status BeginInstance(const std::string& element, std::uint64_t index) {
    element_ = element;
    index_ = index;
    return absl::OkStatus();
  }

  absl::Status Read(PlyType type, double* value) {
    const std::size_t size = SizeOf(type);
    if (data_.size() - pos_ < size) {
      return absl::InvalidArgumentError(absl::StrFormat(
          "%s: truncated binary PLY: data ends inside %s %d (needs %d bytes at offset %d, the file has %d)",
          source_, element_, index_, size, pos_, data_.size()));
    }
    unsigned char raw[8];
    std::memcpy(raw, data_.data() + pos_, size);
    pos_ += size;
    if (big_endian_ != (std::endian::native == std::endian::big)) {
      for (std::size_t i = 0; i < size / 2; ++i) std::swap(raw[i], raw[size - 1 - i]);
    }
    switch (type) {
      case PlyType::kInt8: *value = Decode<std::int8_t>(raw); break;
      case PlyType::kUint8: *value = Decode<std::uint8_t>(raw); break;
      case PlyType::kInt16: *value = Decode<std::int16_t>(raw); break;
      case PlyType::kUint16: *value = Decode<std::uint16_t>(raw); break;
      case PlyType::kInt32: *value = Decode<std::int32_t>(raw); break;
      case PlyType::kUint32: *value = Decode<std::uint32_t>(raw); break;
      case PlyType::kFloat32: *value = Decode<float>(raw); break;
      case PlyType::kFloat64: *value = Decode<double>(raw); break;
    }
    return absl::OkStatus();
  }

  absl::Status EndInstance() { return absl::OkStatus(); }

  absl::Status Finish() {
    if (pos_ != data_.size()) {
      return absl::InvalidArgumentError(absl::StrFormat(
          "%s: binary PLY has %d bytes after the last declared element (offset %d)", source_,
          data_.size() - pos_, pos_));
    }
    return absl::OkStatus();
  }

  std::string Where() const { return absl::StrFormat("%s %d (byte offset %d)", element_, index_, pos_); }

 private:
  template <typename T>
  static double Decode(const unsigned char* raw) {
    T v;
    std::memcpy(&v, raw, sizeof(T));
    return static_cast<double>(v);
  }

  std::string_view data_;
  std::size_t pos_;
  bool big_endian_;
  std::string_view source_;
  std::string element_;
  std::uint64_t index_ = 0;
};

// Which properties of the vertex and face elements we keep.
struct Roles {
  int vertex_element = -1;
  int face_element = -1;
  int axis_property[3] = {-1, -1, -1};  // x, y, z in the vertex element
  int indices_property = -1;            // in the face element
};

absl::StatusOr<Roles> FindRoles(const PlyHeader& header, std::string_view source) {
  Roles roles;
  for (int e = 0; e < static_cast<int>(header.elements.size()); ++e) {
    if (header.elements[e].name == "vertex") roles.vertex_element = e;
    if (header.elements[e].name == "face") roles.face_element = e;
  }
  if (roles.vertex_element < 0) {
    return absl::InvalidArgumentError(absl::StrFormat("%s: PLY header declares no 'vertex' element", source));
  }
  if (roles.face_element < 0) {
    return absl::InvalidArgumentError(absl::StrFormat("%s: PLY header declares no 'face' element", source));
  }
  const PlyElement& vertex = header.elements[roles.vertex_element];
  static constexpr const char* kAxes[3] = {"x", "y", "z"};
  for (int p = 0; p < static_cast<int>(vertex.properties.size()); ++p) {
    for (int axis = 0; axis < 3; ++axis) {
      if (vertex.properties[p].name == kAxes[axis]) roles.axis_property[axis] = p;
    }
  }
  for (int axis = 0; axis < 3; ++axis) {
    const int p = roles.axis_property[axis];
    if (p < 0) {
      return absl::InvalidArgumentError(absl::StrFormat("%s: PLY element 'vertex' (header line %d) has no property '%s'",
                                                        source, vertex.header_line, kAxes[axis]));
    }
    const PlyProperty& property = vertex.properties[p];
    if (property.is_list || IsInteger(property.type)) {
      return absl::InvalidArgumentError(absl::StrFormat(
          "%s: PLY vertex property '%s' must be a float or double scalar", source, kAxes[axis]));
    }
  }
  const PlyElement& face = header.elements[roles.face_element];
  for (int p = 0; p < static_cast<int>(face.properties.size()); ++p) {
    if (face.properties[p].name == "vertex_indices" || face.properties[p].name == "vertex_index") {
      roles.indices_property = p;
    }
  }
  if (roles.indices_property < 0) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "%s: PLY element 'face' (header line %d) has no list property 'vertex_indices'", source, face.header_line));
  }
  const PlyProperty& indices = face.properties[roles.indices_property];
  if (!indices.is_list || !IsInteger(indices.type)) {
    return absl::InvalidArgumentError(
        absl::StrFormat("%s: PLY face property '%s' must be a list of integers", source, indices.name));
  }
  return roles;
}

template <typename Source>
absl::Status ReadBody(const PlyHeader& header, const Roles& roles, Source& data, std::string_view source,
                      ParsedMesh& out) {
  std::vector<int> polygon;
  for (int e = 0; e < static_cast<int>(header.elements.size()); ++e) {
    const PlyElement& element = header.elements[e];
    const bool is_vertex = e == roles.vertex_element;
    const bool is_face = e == roles.face_element;
    for (std::uint64_t i = 0; i < element.count; ++i) {
      SURFMAP_RETURN_IF_ERROR(data.BeginInstance(element.name, i));
      Eigen::Vector3d position = Eigen::Vector3d::Zero();
      polygon.clear();
      for (int p = 0; p < static_cast<int>(element.properties.size()); ++p) {
        const PlyProperty& property = element.properties[p];
        double value = 0.0;
        if (!property.is_list) {
          SURFMAP_RETURN_IF_ERROR(data.Read(property.type, &value));
          if (is_vertex) {
            for (int axis = 0; axis < 3; ++axis) {
              if (roles.axis_property[axis] == p) position[axis] = value;
            }
          }
          continue;
        }
        double count = 0.0;
        SURFMAP_RETURN_IF_ERROR(data.Read(property.count_type, &count));
        if (count < 0 || count > kMaxPolygonSize) {
          return absl::InvalidArgumentError(absl::StrFormat("%s: %s: list '%s' has a bad length %g", source,
                                                            data.Where(), property.name, count));
        }
        const bool keep = is_face && p == roles.indices_property;
        for (int k = 0; k < static_cast<int>(count); ++k) {
          SURFMAP_RETURN_IF_ERROR(data.Read(property.type, &value));
          if (keep) {
            if (value > std::numeric_limits<int>::max()) {
              return absl::InvalidArgumentError(absl::StrFormat("%s: %s: vertex index %.0f is out of range", source,
                                                                data.Where(), value));
            }
            polygon.push_back(static_cast<int>(value));
          }
        }
      }
      SURFMAP_RETURN_IF_ERROR(data.EndInstance());
      if (is_vertex) {
        if (!position.allFinite()) {
          return absl::InvalidArgumentError(absl::StrFormat("%s: %s: non-finite vertex coordinate (%g, %g, %g)",
                                                            source, data.Where(), position.x(), position.y(),
                                                            position.z()));
        }
        out.mesh.positions.push_back(position);
      }
      if (is_face) {
        if (polygon.size() < 3) {
          return absl::InvalidArgumentError(absl::StrFormat("%s: %s: face has %d vertices; a face needs at least 3",
                                                            source, data.Where(), polygon.size()));
        }
        AppendFanTriangles(polygon, absl::StrCat("face ", i), out);
      }
    }
  }
  return data.Finish();
}

}  // namespace

absl::StatusOr<ParsedMesh> ReadPly(std::string_view bytes, std::string_view source) {
  absl::StatusOr<PlyHeader> header = ParseHeader(bytes, source);
  if (!header.ok()) return header.status();
  absl::StatusOr<Roles> roles = FindRoles(*header, source);
  if (!roles.ok()) return roles.status();

  ParsedMesh out;
  absl::Status status;
  if (header->encoding == PlyEncoding::kAscii) {
    AsciiSource data(bytes.substr(header->data_offset), header->data_first_line, source);
    status = ReadBody(*header, *roles, data, source, out);
  } else {
    BinarySource data(bytes, header->data_offset, header->encoding == PlyEncoding::kBinaryBigEndian, source);
    status = ReadBody(*header, *roles, data, source, out);
  }
  if (!status.ok()) return status;
  return out;
}

}  // namespace surfmap
