#include "server/mesh/control_mesh.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <map>
#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include "server/mesh/primitive_meshes.h"
#include "server/mesh/test_data.h"

namespace surfmap {
namespace {

using ::testing::HasSubstr;

// Closed: every undirected edge has exactly two faces.
bool IsClosed(const ControlMesh& mesh) {
  std::map<std::pair<int, int>, int> count;
  for (const auto& t : mesh.triangles) {
    for (int i = 0; i < 3; ++i) ++count[{std::min(t[i], t[(i + 1) % 3]), std::max(t[i], t[(i + 1) % 3])}];
  }
  for (const auto& [edge, n] : count) {
    if (n != 2) return false;
  }
  return true;
}

TEST(ParseControlMeshTest, ReadsTetrahedronObj) {
  absl::StatusOr<ControlMesh> mesh =
      ParseControlMesh(ReadMeshTestData("tetrahedron.obj"), MeshFormat::kObj, "tetrahedron.obj");
  ASSERT_TRUE(mesh.ok()) << mesh.status();
  EXPECT_EQ(mesh->positions.size(), 4u);
  ASSERT_EQ(mesh->triangles.size(), 4u);
  EXPECT_EQ(mesh->positions[1], Eigen::Vector3d(10, -10, -10));
  EXPECT_EQ(mesh->triangles[1], (std::array<int, 3>{0, 3, 1}));
  EXPECT_TRUE(IsClosed(*mesh));
}

TEST(ParseControlMeshTest, FanTriangulatesCubeQuads) {
  absl::StatusOr<ControlMesh> mesh = ParseControlMeshAuto(ReadMeshTestData("cube_quads.obj"), "cube_quads.obj");
  ASSERT_TRUE(mesh.ok()) << mesh.status();
  EXPECT_EQ(mesh->positions.size(), 8u);
  ASSERT_EQ(mesh->triangles.size(), 12u);
  // f 1 4 3 2 -> (1 4 3), (1 3 2), 0-based.
  EXPECT_EQ(mesh->triangles[0], (std::array<int, 3>{0, 3, 2}));
  EXPECT_EQ(mesh->triangles[1], (std::array<int, 3>{0, 2, 1}));
  EXPECT_TRUE(IsClosed(*mesh));
  // Outward winding: every face normal points away from the centre.
  for (const auto& t : mesh->triangles) {
    const Eigen::Vector3d& a = mesh->positions[t[0]];
    const Eigen::Vector3d n = (mesh->positions[t[1]] - a).cross(mesh->positions[t[2]] - a);
    EXPECT_GT(n.dot(a + mesh->positions[t[1]] + mesh->positions[t[2]]), 0.0);
  }
}

TEST(ParseControlMeshTest, ReadsOpenPlate) {
  absl::StatusOr<ControlMesh> mesh = ParseControlMeshAuto(ReadMeshTestData("plate.obj"), "plate.obj");
  ASSERT_TRUE(mesh.ok()) << mesh.status();
  EXPECT_EQ(mesh->positions.size(), 35u);
  EXPECT_EQ(mesh->triangles.size(), 48u);
  EXPECT_FALSE(IsClosed(*mesh));
}

TEST(ParseControlMeshTest, ObjKeepsDoublePrecisionAndNegativeIndices) {
  const std::string obj =
      "v 123.456789012345678 0 0\nv 0 1e-3 0\nv 0 0 +7.25\n"
      "f -3 -2 -1\n";
  absl::StatusOr<ControlMesh> mesh = ParseControlMesh(obj, MeshFormat::kObj, "upload");
  ASSERT_TRUE(mesh.ok()) << mesh.status();
  EXPECT_EQ(mesh->positions[0].x(), 123.456789012345678);
  EXPECT_EQ(mesh->positions[2].z(), 7.25);
  EXPECT_EQ(mesh->triangles[0], (std::array<int, 3>{0, 1, 2}));
}

TEST(ParseControlMeshTest, AsciiAndBinaryPlyAgree) {
  const ControlMesh reference = MakeIcosahedron(25.0);
  for (const char* name : {"icosahedron.ply", "icosahedron_binary_le.ply", "icosahedron_binary_be.ply"}) {
    SCOPED_TRACE(name);
    absl::StatusOr<ControlMesh> mesh = ParseControlMeshAuto(ReadMeshTestData(name), name);
    ASSERT_TRUE(mesh.ok()) << mesh.status();
    ASSERT_EQ(mesh->positions.size(), 12u);
    EXPECT_EQ(mesh->triangles, reference.triangles);
    // The little-endian file stores floats: ~1e-6 relative.
    for (int v = 0; v < 12; ++v) EXPECT_LT((mesh->positions[v] - reference.positions[v]).norm(), 1e-5) << v;
  }
}

TEST(WriteObjTest, RoundTripsExactly) {
  absl::StatusOr<ControlMesh> bottle = MakeBottle();
  ASSERT_TRUE(bottle.ok());
  absl::StatusOr<ControlMesh> back = ParseControlMesh(WriteObj(*bottle), MeshFormat::kObj, "roundtrip");
  ASSERT_TRUE(back.ok()) << back.status();
  EXPECT_EQ(back->positions, bottle->positions);
  EXPECT_EQ(back->triangles, bottle->triangles);
}

// Binary PLY bytes for a given endianness (tests both byte orders of every
// scalar type the reader decodes, including skipped lists).
template <typename T>
void Put(std::string& out, T value, bool big_endian) {
  char raw[sizeof(T)];
  std::memcpy(raw, &value, sizeof(T));
  if (big_endian != (std::endian::native == std::endian::big)) std::reverse(raw, raw + sizeof(T));
  out.append(raw, sizeof(T));
}

std::string BinaryTetrahedronPly(bool big_endian) {
  const ControlMesh tet = MakeTetrahedron(10.0);
  std::string out = std::string("ply\nformat ") + (big_endian ? "binary_big_endian" : "binary_little_endian") +
                    " 1.0\nelement vertex 4\nproperty double x\nproperty ushort skip\nproperty double y\n"
                    "property double z\nelement face 4\nproperty list uchar uint vertex_indices\n"
                    "property list int double skip_list\nend_header\n";
  for (const Eigen::Vector3d& p : tet.positions) {
    Put<double>(out, p.x(), big_endian);
    Put<std::uint16_t>(out, 513, big_endian);
    Put<double>(out, p.y(), big_endian);
    Put<double>(out, p.z(), big_endian);
  }
  for (const auto& t : tet.triangles) {
    Put<std::uint8_t>(out, 3, big_endian);
    for (int v : t) Put<std::uint32_t>(out, static_cast<std::uint32_t>(v), big_endian);
    Put<std::int32_t>(out, 2, big_endian);
    Put<double>(out, 1.5, big_endian);
    Put<double>(out, -2.5, big_endian);
  }
  return out;
}

TEST(ParseControlMeshTest, BinaryPlyBothByteOrders) {
  const ControlMesh tet = MakeTetrahedron(10.0);
  for (bool big_endian : {false, true}) {
    absl::StatusOr<ControlMesh> mesh = ParseControlMeshAuto(BinaryTetrahedronPly(big_endian), "tet.ply");
    ASSERT_TRUE(mesh.ok()) << mesh.status();
    EXPECT_EQ(mesh->positions, tet.positions);
    EXPECT_EQ(mesh->triangles, tet.triangles);
  }
}

struct BrokenMesh {
  const char* name;
  std::string bytes;
  MeshFormat format;
  std::vector<std::string> fragments;  // every one must be in the message
};

std::string TruncatedBinaryPly() {
  std::string bytes = BinaryTetrahedronPly(false);
  bytes.resize(bytes.size() - 30);
  return bytes;
}

std::string BinaryPlyWithTrailingBytes() { return BinaryTetrahedronPly(true) + "xyz"; }

const std::string kPlyHeader3 =
    "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
    "element face 1\nproperty list uchar int vertex_indices\nend_header\n";

std::vector<BrokenMesh> BrokenMeshes() {
  return {
      {"empty", "", MeshFormat::kObj, {"upload", "empty mesh", "no vertices"}},
      {"comments only", "# nothing\n\n", MeshFormat::kObj, {"no vertices"}},
      {"no faces", "v 0 0 0\nv 1 0 0\nv 0 1 0\n", MeshFormat::kObj, {"empty mesh", "no faces"}},
      {"nan coordinate", "v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n", MeshFormat::kObj,
       {"line 2", "'nan'", "not finite"}},
      {"inf coordinate", "v 0 0 0\nv 1 0 0\nv 0 1e999 0\nf 1 2 3\n", MeshFormat::kObj, {"line 3", "not finite"}},
      {"garbage coordinate", "v 0 0 0\nv 1 x 0\nv 0 1 0\nf 1 2 3\n", MeshFormat::kObj, {"line 2", "'x' is not a number"}},
      {"missing coordinate", "v 0 0\n", MeshFormat::kObj, {"line 1", "needs 3 coordinates"}},
      {"out-of-range index", "v 0 0 0\nv 1 0 0\nv 0 1 0\n# x\nf 1 2 9\n", MeshFormat::kObj,
       {"line 5", "index 9 is out of range", "3 vertices"}},
      {"zero index", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n", MeshFormat::kObj, {"OBJ parse error", "line 4"}},
      {"two-vertex face", "v 0 0 0\nv 1 0 0\nf 1 2\n", MeshFormat::kObj, {"line 3", "at least 3"}},
      {"repeated index", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 1 2\n", MeshFormat::kObj,
       {"triangle 1", "line 5", "repeats a vertex index (0, 0, 1)"}},
      {"zero-area face", "v 0 0 0\nv 1 0 0\nv 2 0 0\nv 0 1 0\nf 1 2 4\nf 1 3 2\n", MeshFormat::kObj,
       {"triangle 1", "line 6", "zero area"}},
      {"non-manifold edge",
       "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 -1 0\nv 0 0 1\nf 1 2 3\nf 2 1 4\nf 1 2 5\n", MeshFormat::kObj,
       {"non-manifold edge (0, 1)", "line 6", "line 7", "line 8"}},
      {"inconsistent orientation", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 3\nf 2 3 4\n", MeshFormat::kObj,
       {"inconsistent orientation", "line 5", "line 6", "edge 1->2"}},
      {"unreferenced vertex", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 5 5 5\nf 1 2 3\n", MeshFormat::kObj,
       {"vertex 3 is unreferenced"}},
      // Found by fuzzing (tests/fuzz): tinyobjloader ends a line at a NUL, the
      // pre-scan did not, and their face counts disagreed (was INTERNAL).
      {"NUL byte in a face", std::string("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 2 3 4\nf 1 4 3") + '\0' + " 2\n",
       MeshFormat::kObj, {"line 8", "NUL byte at column 8"}},
      {"carriage-return line ends, bad index", "v 0 0 0\rv 1 0 0\rv 0 1 0\r# x\rf 1 2 9\r", MeshFormat::kObj,
       {"line 5", "index 9 is out of range"}},
      {"256-gon face, carriage-return line ends", [] {
         std::string obj;
         for (int k = 0; k < 256; ++k) obj += "v " + std::to_string(k) + " " + std::to_string(k % 7) + " 0\r";
         obj += "f";
         for (int k = 1; k <= 256; ++k) obj += " " + std::to_string(k);
         return obj + "\r";
       }(), MeshFormat::kObj, {"line 257", "a face with 256 vertices", "the limit is 255 vertices per polygon"}},
      {"ply no magic", "plx\nformat ascii 1.0\nend_header\n", MeshFormat::kPly, {"header line 1", "'ply'"}},
      {"ply bad version", "ply\nformat ascii 2.0\nend_header\n", MeshFormat::kPly,
       {"header line 2", "unsupported PLY version '2.0'"}},
      {"ply bad format", "ply\nformat binary_middle_endian 1.0\nend_header\n", MeshFormat::kPly,
       {"unknown format 'binary_middle_endian'"}},
      {"ply unknown keyword", "ply\nformat ascii 1.0\nelement vertex 0\nbogus\nend_header\n", MeshFormat::kPly,
       {"header line 4", "unknown header keyword 'bogus'"}},
      {"ply unknown type", "ply\nformat ascii 1.0\nelement vertex 0\nproperty float128 x\nend_header\n",
       MeshFormat::kPly, {"header line 4", "unknown property type 'float128'"}},
      {"ply property first", "ply\nformat ascii 1.0\nproperty float x\nend_header\n", MeshFormat::kPly,
       {"property before any element"}},
      {"ply no end_header", "ply\nformat ascii 1.0\nelement vertex 0\n", MeshFormat::kPly, {"no end_header"}},
      {"ply missing y",
       "ply\nformat ascii 1.0\nelement vertex 0\nproperty float x\nproperty float z\nelement face 0\n"
       "property list uchar int vertex_indices\nend_header\n",
       MeshFormat::kPly, {"no property 'y'"}},
      {"ply integer coordinates",
       "ply\nformat ascii 1.0\nelement vertex 0\nproperty int x\nproperty float y\nproperty float z\n"
       "element face 0\nproperty list uchar int vertex_indices\nend_header\n",
       MeshFormat::kPly, {"'x' must be a float or double"}},
      {"ply no faces element",
       "ply\nformat ascii 1.0\nelement vertex 0\nproperty float x\nproperty float y\nproperty float z\nend_header\n",
       MeshFormat::kPly, {"no 'face' element"}},
      {"ply too few values", kPlyHeader3 + "0 0 0\n1 0\n0 1 0\n3 0 1 2\n", MeshFormat::kPly,
       {"PLY line 11", "vertex 1", "too few values"}},
      {"ply too many values", kPlyHeader3 + "0 0 0\n1 0 0 9\n0 1 0\n3 0 1 2\n", MeshFormat::kPly,
       {"PLY line 11", "4 values, expected 3"}},
      {"ply non-finite", kPlyHeader3 + "0 0 0\n1 0 0\n0 inf 0\n3 0 1 2\n", MeshFormat::kPly,
       {"vertex 2", "non-finite"}},
      {"ply out-of-range index", kPlyHeader3 + "0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n", MeshFormat::kPly,
       {"face 0", "references vertex 7, out of range"}},
      {"ply repeated index", kPlyHeader3 + "0 0 0\n1 0 0\n0 1 0\n3 0 1 1\n", MeshFormat::kPly,
       {"face 0", "repeats a vertex index"}},
      {"ply data missing", kPlyHeader3 + "0 0 0\n1 0 0\n0 1 0\n", MeshFormat::kPly, {"data ends before face 0"}},
      {"ply trailing data", kPlyHeader3 + "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n1 2 3\n", MeshFormat::kPly,
       {"data after the last declared element"}},
      {"ply index overflows its type", kPlyHeader3 + "0 0 0\n1 0 0\n0 1 0\n300 0 1 2\n", MeshFormat::kPly,
       {"'300' is not a value in range"}},
      {"truncated binary ply", TruncatedBinaryPly(), MeshFormat::kPly,
       {"truncated binary PLY", "face 3", "the file has"}},
      {"binary ply trailing bytes", BinaryPlyWithTrailingBytes(), MeshFormat::kPly, {"3 bytes after the last"}},
  };
}

TEST(ParseControlMeshTest, RejectsBrokenMeshesWithClearMessages) {
  for (const BrokenMesh& broken : BrokenMeshes()) {
    SCOPED_TRACE(broken.name);
    absl::StatusOr<ControlMesh> mesh = ParseControlMesh(broken.bytes, broken.format, "upload");
    ASSERT_FALSE(mesh.ok());
    EXPECT_EQ(mesh.status().code(), absl::StatusCode::kInvalidArgument);
    EXPECT_THAT(std::string(mesh.status().message()), HasSubstr("upload"));
    for (const std::string& fragment : broken.fragments) {
      EXPECT_THAT(std::string(mesh.status().message()), HasSubstr(fragment));
    }
  }
}

// Found by fuzzing (tests/fuzz): a lone '\r' ends a line for tinyobjloader but
// did not for the pre-scan, so a file with classic Mac line ends was rejected
// ("found 4 vertices where the text has 1") and a '\r' inside a face line made
// the two readers disagree on the faces (INTERNAL). Every line-end style now
// reads the same mesh.
TEST(ParseControlMeshTest, ObjReadsEveryLineEndStyle) {
  const std::string lf = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 2 3 4\nf 1 4 3\n";
  const absl::StatusOr<ControlMesh> expected = ParseControlMesh(lf, MeshFormat::kObj, "lf");
  ASSERT_TRUE(expected.ok()) << expected.status();
  ASSERT_EQ(expected->triangles.size(), 4u);
  auto replace_line_ends = [&](const std::string& end) {
    std::string out;
    for (char c : lf) out += c == '\n' ? end : std::string(1, c);
    return out;
  };
  std::string mixed = lf;
  mixed[mixed.find("\nf 2 3 4")] = '\r';  // one face line ended by a lone '\r'
  for (const std::string& bytes : {replace_line_ends("\r\n"), replace_line_ends("\r"), mixed}) {
    const absl::StatusOr<ControlMesh> mesh = ParseControlMesh(bytes, MeshFormat::kObj, "upload");
    ASSERT_TRUE(mesh.ok()) << mesh.status();
    EXPECT_EQ(mesh->positions, expected->positions);
    EXPECT_EQ(mesh->triangles, expected->triangles);
  }
}

TEST(ValidateControlMeshTest, NamesTheTriangle) {
  ControlMesh mesh = MakeTetrahedron(1.0);
  EXPECT_TRUE(ValidateControlMesh(mesh).ok());
  mesh.triangles[2] = {0, 3, 2};  // flipped
  const absl::Status flipped = ValidateControlMesh(mesh);
  EXPECT_THAT(std::string(flipped.message()), HasSubstr("inconsistent orientation"));
  EXPECT_THAT(std::string(flipped.message()), HasSubstr("triangle 2"));

  mesh = MakeTetrahedron(1.0);
  mesh.positions[3] = Eigen::Vector3d(NAN, 0, 0);
  EXPECT_THAT(std::string(ValidateControlMesh(mesh).message()), HasSubstr("vertex 3 has a non-finite coordinate"));

  mesh = MakeTetrahedron(1.0);
  mesh.triangles[3][1] = -1;
  EXPECT_THAT(std::string(ValidateControlMesh(mesh).message()), HasSubstr("triangle 3 references vertex -1"));

  EXPECT_THAT(std::string(ValidateControlMesh(ControlMesh{}).message()), HasSubstr("empty mesh"));
}

TEST(ValidateControlMeshTest, ZeroAreaToleranceIsRelativeToMeshSize) {
  // A sliver of relative area 1e-8 is accepted at any scale; a collinear
  // triple (area ~ rounding) is rejected at any scale.
  for (double scale : {1e-3, 1.0, 1e4}) {
    ControlMesh sliver;
    sliver.positions = {{0, 0, 0}, {scale, 0, 0}, {0.5 * scale, 1e-8 * scale, 0}};
    sliver.triangles = {{0, 1, 2}};
    EXPECT_TRUE(ValidateControlMesh(sliver).ok()) << scale;
    ControlMesh flat = sliver;
    flat.positions[2] = {0.3 * scale, 0, 0};
    EXPECT_FALSE(ValidateControlMesh(flat).ok()) << scale;
  }
}

}  // namespace
}  // namespace surfmap
