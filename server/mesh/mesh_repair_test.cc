#include "server/mesh/mesh_repair.h"

#include <string>

#include "absl/strings/str_cat.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "server/mesh/mesh_units.h"
#include "server/mesh/primitive_meshes.h"
#include "server/mesh/scan_like_mesh.h"

namespace surfmap {
namespace {

using ::testing::HasSubstr;

int CountOf(const RepairedMesh& r, const std::string& kind) {
  for (const MeshRepairNote& n : r.repairs) {
    if (n.kind == kind) return n.count;
  }
  return 0;
}

TEST(MeshRepair, CleanMeshIsUnchangedAndReportsNothing) {
  const ControlMesh cube_like = MakeOctahedron(10.0);
  absl::StatusOr<RepairedMesh> r = ParseAndRepairMesh(WriteObj(cube_like), MeshFormat::kObj, "clean.obj", 1.0);
  ASSERT_TRUE(r.ok()) << r.status();
  EXPECT_TRUE(r->repairs.empty());
  EXPECT_EQ(r->mesh.positions, cube_like.positions);
  EXPECT_EQ(r->mesh.triangles, cube_like.triangles);
}

TEST(MeshRepair, ScanInMetresWithStrayVerticesIsScaledAndCleaned) {
  absl::StatusOr<ControlMesh> scan = MakeScanLikeMesh();
  ASSERT_TRUE(scan.ok()) << scan.status();
  ASSERT_GE(scan->triangles.size(), 20000u);
  const std::string obj = WriteObjScaled(*scan, 1000.0, 37);
  absl::StatusOr<RepairedMesh> r = ParseAndRepairMesh(obj, MeshFormat::kObj, "scan_m.obj", 1000.0);
  ASSERT_TRUE(r.ok()) << r.status();
  EXPECT_EQ(CountOf(*r, "unreferenced_vertices_removed"), 37);
  EXPECT_EQ(r->mesh.positions.size(), scan->positions.size());
  EXPECT_EQ(r->mesh.triangles, scan->triangles);
  // Text in metres, read back in mm: within the text's shortest round trip.
  for (std::size_t v = 0; v < scan->positions.size(); ++v) {
    ASSERT_LT((r->mesh.positions[v] - scan->positions[v]).norm(), 1e-9) << "vertex " << v;
  }
  const Eigen::Vector3d extent = BoundingBoxSize(r->mesh);
  EXPECT_NEAR(extent.x(), 120.0, 5.0);  // radii 60 mm +- bumps of 1.5 mm
}

TEST(MeshRepair, RepeatedVertexPolygonIsFixedAndReported) {
  // A quad written as a pentagon with its third corner repeated.
  const std::string obj = "v 0 0 0\nv 10 0 0\nv 10 10 0\nv 0 10 0\nf 1 2 3 3 4\n";
  absl::StatusOr<RepairedMesh> r = ParseAndRepairMesh(obj, MeshFormat::kObj, "quad.obj", 1.0);
  ASSERT_TRUE(r.ok()) << r.status();
  EXPECT_EQ(CountOf(*r, "repeated_vertex_polygons_fixed"), 1);
  EXPECT_EQ(r->mesh.triangles.size(), 2u);
  // The strict reader still refuses it, naming the line.
  absl::StatusOr<ControlMesh> strict = ParseControlMesh(obj, MeshFormat::kObj, "quad.obj");
  ASSERT_FALSE(strict.ok());
  EXPECT_THAT(std::string(strict.status().message()), HasSubstr("triangle 0 (face on line 5) repeats a vertex index (0, 1, 2, 2, 3)"));
}

TEST(MeshRepair, DuplicateVerticesDuplicateAndDegenerateFacesAreRepaired) {
  // Two triangles of a square written with their own corners (as STL does),
  // the second corner of the shared edge off by 1e-9 mm; plus the first face
  // again, and a zero-area face on the diagonal.
  const std::string obj =
      "v 0 0 0\nv 10 0 0\nv 10 10 0\n"
      "v 0 0 0\nv 10 10.000000001 0\nv 0 10 0\n"
      "v 5 5 0\n"
      "f 1 2 3\nf 4 5 6\nf 1 2 3\nf 1 3 7\n";
  absl::StatusOr<RepairedMesh> r = ParseAndRepairMesh(obj, MeshFormat::kObj, "square.obj", 1.0);
  ASSERT_TRUE(r.ok()) << r.status();
  EXPECT_EQ(CountOf(*r, "duplicate_vertices_welded"), 2);
  EXPECT_EQ(CountOf(*r, "duplicate_faces_removed"), 1);
  EXPECT_EQ(CountOf(*r, "degenerate_faces_removed"), 1);
  EXPECT_EQ(CountOf(*r, "unreferenced_vertices_removed"), 1);  // vertex 7 was only on the zero-area face
  EXPECT_EQ(r->mesh.positions.size(), 4u);
  EXPECT_EQ(r->mesh.triangles.size(), 2u);
}

TEST(MeshRepair, HarmfulDefectsAreStillRejected) {
  // Three faces on one edge.
  const std::string obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 -1 0\nv 0 0 1\nf 1 2 3\nf 2 1 4\nf 1 2 5\n";
  absl::StatusOr<RepairedMesh> r = ParseAndRepairMesh(obj, MeshFormat::kObj, "fan.obj", 1.0);
  ASSERT_FALSE(r.ok());
  EXPECT_THAT(std::string(r.status().message()), HasSubstr("non-manifold edge"));
  EXPECT_THAT(std::string(r.status().message()), HasSubstr("face on line"));
  EXPECT_FALSE(ParseAndRepairMesh("v 0 0 0\n", MeshFormat::kObj, "x", 0.0).ok());  // bad scale
}

TEST(MeshRepair, StlBinaryAndAsciiReadBackTheMesh) {
  absl::StatusOr<ControlMesh> scan = MakeScanLikeMesh({.subdivisions = 3});
  ASSERT_TRUE(scan.ok());
  for (const bool binary : {true, false}) {
    SCOPED_TRACE(binary ? "binary" : "ascii");
    const std::string stl = binary ? WriteStlBinary(*scan) : WriteStlAscii(*scan);
    EXPECT_EQ(GuessMeshFormat(stl), MeshFormat::kStl);
    absl::StatusOr<RepairedMesh> r = ParseAndRepairMesh(stl, MeshFormat::kStl, "scan.stl", 1.0);
    ASSERT_TRUE(r.ok()) << r.status();
    // Shared corners are bit-identical in the file: merged by the reader, no repair.
    EXPECT_TRUE(r->repairs.empty()) << r->repairs[0].kind;
    EXPECT_EQ(r->mesh.positions.size(), scan->positions.size());
    EXPECT_EQ(r->mesh.triangles.size(), scan->triangles.size());
    // float32 in binary: 6e-8 relative of ~60 mm.
    const double tolerance = binary ? 1e-5 : 1e-12;
    for (std::size_t t = 0; t < scan->triangles.size(); ++t) {
      for (int c = 0; c < 3; ++c) {
        ASSERT_LT((r->mesh.positions[r->mesh.triangles[t][c]] - scan->positions[scan->triangles[t][c]]).norm(),
                  tolerance);
      }
    }
  }
}

TEST(MeshRepair, MalformedStlIsRejectedWithThePlace) {
  absl::StatusOr<ControlMesh> mesh = MakeScanLikeMesh({.subdivisions = 1});
  ASSERT_TRUE(mesh.ok());
  std::string binary = WriteStlBinary(*mesh);
  binary.pop_back();  // truncated
  absl::StatusOr<RepairedMesh> r = ParseAndRepairMesh(binary, MeshFormat::kStl, "cut.stl", 1.0);
  ASSERT_FALSE(r.ok());
  EXPECT_THAT(std::string(r.status().message()), HasSubstr("truncated or trailing"));
  const std::string ascii = "solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 nan\n";
  r = ParseAndRepairMesh(ascii, MeshFormat::kStl, "nan.stl", 1.0);
  ASSERT_FALSE(r.ok());
  EXPECT_THAT(std::string(r.status().message()), HasSubstr("nan.stl line 5"));
}

TEST(MeshUnits, ImplausibleSizesAreRefusedAndUnusualOnesWarned) {
  std::vector<std::string> warnings;
  // A 200 mm object whose file is in metres but read as mm: 0.2 mm.
  absl::Status tiny = CheckObjectSize({0.2, 0.1, 0.1}, "mm", &warnings);
  EXPECT_EQ(tiny.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(std::string(tiny.message()), HasSubstr("implausibly small"));
  EXPECT_FALSE(CheckObjectSize({20000, 1, 1}, "mm", &warnings).ok());
  EXPECT_TRUE(CheckObjectSize({200, 100, 50}, "m", &warnings).ok());
  EXPECT_TRUE(warnings.empty());
  EXPECT_TRUE(CheckObjectSize({10, 10, 10}, "mm", &warnings).ok());
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_THAT(warnings[0], HasSubstr("small"));
  EXPECT_DOUBLE_EQ(MmPerUnit(LengthUnit::kIn), 25.4);
}

}  // namespace
}  // namespace surfmap
