#include "clients/sim/rig/scene.h"

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <string>

#include <gtest/gtest.h>
#include "absl/strings/str_cat.h"
#include "clients/sim/rig/surface_score.h"
#include "server/mesh/loop_surface.h"
#include "server/mesh/primitive_meshes.h"

namespace surfmap {
namespace {

namespace fs = std::filesystem;

// A scratch directory holding a tetrahedron mesh "tet.obj" (radius 10).
class SceneFilesTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("surfmap_scene_test_" + std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    std::ofstream(dir_ / "tet.obj") << WriteObj(MakeTetrahedron(10.0));
  }
  void TearDown() override { fs::remove_all(dir_); }

  absl::StatusOr<Scene> Parse(const std::string& json) { return ParseScene(json, "test.json", dir_); }

  // A valid scene with `regions` spliced in.
  static std::string SceneJson(const std::string& regions, const std::string& extra = "") {
    return R"({"name": "t", "mesh": "tet.obj", "default_material": "glass", )" + extra +
           R"("materials": {"glass": {"mu": 0.1, "a1": 0, "a2": 0, "sigma": 0.01},
                            "rubber": {"mu": 0.3, "a1": 0.6, "a2": 0.25, "sigma": 0.11}},
              "regions": [)" + regions + "]}";
  }

  void ExpectError(const std::string& json, absl::StatusCode code, const std::string& fragment) {
    absl::StatusOr<Scene> scene = Parse(json);
    ASSERT_FALSE(scene.ok()) << "accepted: " << json;
    EXPECT_EQ(scene.status().code(), code) << scene.status();
    EXPECT_NE(scene.status().message().find(fragment), std::string::npos)
        << "message '" << scene.status().message() << "' lacks '" << fragment << "'";
  }

  fs::path dir_;
};

TEST_F(SceneFilesTest, ParsesMaterialsRegionsAndMesh) {
  auto scene = Parse(SceneJson(R"({"material": "rubber", "shape": "sphere", "center": [0, 0, 10], "radius": 3},
                                  {"material": "glass", "shape": "box", "min": [-1, -1, -1], "max": [1, 1, 1]})",
                               R"("seed": 7, )"));
  ASSERT_TRUE(scene.ok()) << scene.status();
  EXPECT_EQ(scene->name, "t");
  EXPECT_EQ(scene->seed, 7u);
  EXPECT_EQ(scene->mesh.positions.size(), 4u);
  ASSERT_EQ(scene->material_names, (std::vector<std::string>{"glass", "rubber"}));
  EXPECT_DOUBLE_EQ(scene->materials[1].a2, 0.25);
  EXPECT_EQ(scene->regions.size(), 2u);
  EXPECT_DOUBLE_EQ(scene->MaterialAt({0, 0, 9}).mu, 0.3);   // in the sphere
  EXPECT_DOUBLE_EQ(scene->MaterialAt({0, 0, 14}).mu, 0.1);  // outside: default
  EXPECT_EQ(scene->MaterialIndexAt({0, 0, 0}), 0);          // box -> glass
}

TEST_F(SceneFilesTest, SurfaceSaysWhetherTheFacetsAreTheObject) {
  absl::StatusOr<Scene> loop = Parse(SceneJson(""));
  ASSERT_TRUE(loop.ok()) << loop.status();
  EXPECT_FALSE(loop->facets);  // a control mesh unless the file says otherwise
  absl::StatusOr<Scene> control = Parse(SceneJson("", R"("surface": "control_mesh", )"));
  ASSERT_TRUE(control.ok()) << control.status();
  EXPECT_FALSE(control->facets);
  absl::StatusOr<Scene> facets = Parse(SceneJson("", R"("surface": "facets", )"));
  ASSERT_TRUE(facets.ok()) << facets.status();
  EXPECT_TRUE(facets->facets);
  ExpectError(SceneJson("", R"("surface": "mesh", )"), absl::StatusCode::kInvalidArgument,
              "test.json: surface: unsupported 'mesh' (control_mesh or facets)");
  ExpectError(SceneJson("", R"("surface": true, )"), absl::StatusCode::kInvalidArgument, "surface");
}

TEST_F(SceneFilesTest, FirstMatchingRegionWins) {
  auto scene = Parse(SceneJson(R"({"material": "rubber", "shape": "sphere", "center": [0, 0, 0], "radius": 5},
                                  {"material": "glass", "shape": "sphere", "center": [0, 0, 0], "radius": 10})"));
  ASSERT_TRUE(scene.ok()) << scene.status();
  EXPECT_EQ(scene->MaterialIndexAt({1, 0, 0}), 1);
  EXPECT_EQ(scene->MaterialIndexAt({7, 0, 0}), 0);
}

TEST_F(SceneFilesTest, CylinderPatchSelectsAngleHeightAndRadius) {
  auto scene = Parse(SceneJson(R"({"material": "rubber", "shape": "cylinder_patch", "axis_point": [0, 0, 0],
                                   "axis": [0, 0, 2], "angle_deg": [150, 210], "height": [10, 20],
                                   "radial": [30, 50]})"));
  ASSERT_TRUE(scene.ok()) << scene.status();
  auto at = [&](double deg, double r, double z) {
    const double a = deg * M_PI / 180.0;
    return scene->MaterialIndexAt({r * std::cos(a), r * std::sin(a), z});
  };
  EXPECT_EQ(at(180, 40, 15), 1);
  EXPECT_EQ(at(-170, 40, 15), 1);  // 190 deg: the range runs past 180
  EXPECT_EQ(at(145, 40, 15), 0);
  EXPECT_EQ(at(215, 40, 15), 0);
  EXPECT_EQ(at(180, 40, 21), 0);
  EXPECT_EQ(at(180, 40, 9), 0);
  EXPECT_EQ(at(180, 25, 15), 0);
  EXPECT_EQ(at(180, 55, 15), 0);
}

TEST_F(SceneFilesTest, OrientedBoxSelectsAlongItsOwnAxes) {
  // A strip 2 mm wide (along v) and 40 mm long (along u) at 45 degrees in xy.
  auto scene = Parse(SceneJson(R"({"material": "rubber", "shape": "oriented_box", "center": [0, 0, 0],
                                   "u": [1, 1, 0], "v": [-1, 1.5, 0], "half_size": [20, 1, 5]})"));
  ASSERT_TRUE(scene.ok()) << scene.status();
  const int rubber = scene->FindMaterial("rubber");
  EXPECT_EQ(scene->MaterialIndexAt({10, 10, 0}), rubber);    // along u
  EXPECT_EQ(scene->MaterialIndexAt({10.6, 9.4, 4}), rubber);  // 0.85 mm across, 4 mm along w
  EXPECT_NE(scene->MaterialIndexAt({10.8, 9.2, 0}), rubber);  // 1.13 mm across
  EXPECT_NE(scene->MaterialIndexAt({15, 15, 0}), rubber);     // 21.2 mm along
  EXPECT_NE(scene->MaterialIndexAt({0, 0, 6}), rubber);       // beyond w
}

TEST_F(SceneFilesTest, PolygonDecalSelectsInsideItsOutlineProjectedAlongW) {
  // An L in the plane x = 0 (u = y, v = z, w = x), arms 10 mm wide and 30 mm
  // long, its inner corner at (-5, -5); only x in [-2, 8] (the decal's depth).
  auto scene = Parse(SceneJson(R"({"material": "rubber", "shape": "polygon_decal", "center": [0, 0, 0],
                                   "u": [0, 1, 0], "v": [0, 0, 1], "depth": [-2, 8],
                                   "polygon": [[-15, -15], [15, -15], [15, -5], [-5, -5], [-5, 15], [-15, 15]]})"));
  ASSERT_TRUE(scene.ok()) << scene.status();
  const int rubber = scene->FindMaterial("rubber");
  EXPECT_EQ(scene->MaterialIndexAt({0, 10, -10}), rubber);   // the foot
  EXPECT_EQ(scene->MaterialIndexAt({7, -10, 10}), rubber);   // the upright, 7 mm along w
  EXPECT_EQ(scene->MaterialIndexAt({0, -5.5, -5.5}), rubber);  // just inside the inner corner
  EXPECT_NE(scene->MaterialIndexAt({0, -4.5, -4.5}), rubber);  // just past it: the L's notch
  EXPECT_NE(scene->MaterialIndexAt({0, 10, 10}), rubber);    // deep in the notch
  EXPECT_NE(scene->MaterialIndexAt({0, 15.5, -10}), rubber);  // beyond the foot's end
  EXPECT_NE(scene->MaterialIndexAt({9, 10, -10}), rubber);   // beyond the depth
  EXPECT_NE(scene->MaterialIndexAt({-3, 10, -10}), rubber);
}

TEST_F(SceneFilesTest, PolygonDecalKeepsATrianglesSharpCorner) {
  // A triangle with a 20-degree apex at v = 40: 1 mm below the apex it is
  // 0.35 mm wide; points 0.3 mm either side of that sliver are outside.
  const double half = 40.0 * std::tan(10.0 * std::numbers::pi / 180.0);
  auto scene = Parse(SceneJson(absl::StrCat(R"({"material": "rubber", "shape": "polygon_decal", "center": [0, 0, 0],
                                   "u": [1, 0, 0], "v": [0, 1, 0], "depth": [-1, 1], "polygon": [[)",
                                            -half, ", 0], [", half, R"(, 0], [0, 40]]})")));
  ASSERT_TRUE(scene.ok()) << scene.status();
  const int rubber = scene->FindMaterial("rubber");
  EXPECT_EQ(scene->MaterialIndexAt({0, 39, 0}), rubber);
  EXPECT_NE(scene->MaterialIndexAt({0.3, 39, 0}), rubber);
  EXPECT_NE(scene->MaterialIndexAt({-0.3, 39, 0}), rubber);
  EXPECT_NE(scene->MaterialIndexAt({0, 40.5, 0}), rubber);
}

TEST_F(SceneFilesTest, UnitsScaleMeshAndRegionsToMillimetres) {
  auto scene = Parse(SceneJson(R"({"material": "rubber", "shape": "sphere", "center": [0, 0, 0], "radius": 0.5})",
                               R"("units": "cm", )"));
  ASSERT_TRUE(scene.ok()) << scene.status();
  EXPECT_NEAR(scene->mesh.positions[0].norm(), 100.0, 1e-9);  // 10 cm
  EXPECT_EQ(scene->MaterialIndexAt({4.9, 0, 0}), 1);           // 0.5 cm = 5 mm
  EXPECT_EQ(scene->MaterialIndexAt({5.1, 0, 0}), 0);
}

TEST_F(SceneFilesTest, RejectsInvalidScenes) {
  ExpectError("{not json", absl::StatusCode::kInvalidArgument, "test.json: invalid JSON");
  ExpectError(SceneJson("", R"("colour": 1, )"), absl::StatusCode::kInvalidArgument, "unknown key 'colour'");
  ExpectError(R"({"name": "t", "mesh": "tet.obj", "materials": {"g": {"mu": 0.1, "a1": 0, "a2": 0, "sigma": 0}}})",
              absl::StatusCode::kInvalidArgument, "missing required key 'default_material'");
  ExpectError(SceneJson(R"({"material": "steel", "shape": "sphere", "center": [0, 0, 0], "radius": 1})"),
              absl::StatusCode::kInvalidArgument, "regions[0].material: unknown material 'steel'");
  ExpectError(SceneJson(R"({"material": "glass", "shape": "sphere", "center": [0, 0, 0], "radius": -1})"),
              absl::StatusCode::kInvalidArgument, "regions[0].radius");
  ExpectError(SceneJson(R"({"material": "glass", "shape": "box", "min": [0, 0, 0], "max": [1, -1, 1]})"),
              absl::StatusCode::kInvalidArgument, "box min[1]");
  ExpectError(SceneJson(R"({"material": "glass", "shape": "cone"})"), absl::StatusCode::kInvalidArgument,
              "unknown shape 'cone'");
  ExpectError(SceneJson(R"({"material": "glass", "shape": "oriented_box", "center": [0, 0, 0], "u": [1, 0, 0],
                           "v": [2, 0, 0], "half_size": [1, 1, 1]})"),
              absl::StatusCode::kInvalidArgument, "regions[0].v: must be non-zero and not parallel to u");
  ExpectError(SceneJson(R"({"material": "glass", "shape": "oriented_box", "center": [0, 0, 0], "u": [1, 0, 0],
                           "v": [0, 1, 0], "half_size": [1, 0, 1]})"),
              absl::StatusCode::kInvalidArgument, "regions[0].half_size[1]: 0 must be > 0");
  ExpectError(SceneJson(R"({"material": "glass", "shape": "sphere", "center": [0, 0], "radius": 1})"),
              absl::StatusCode::kInvalidArgument, "regions[0].center: must be an array of 3 numbers");
  ExpectError(SceneJson(R"({"material": "glass", "shape": "cylinder_patch", "axis_point": [0, 0, 0],
                           "axis": [0, 0, 1], "angle_deg": [20, 10], "height": [0, 1]})"),
              absl::StatusCode::kInvalidArgument, "regions[0].angle_deg: is empty or inverted");
  ExpectError(SceneJson(R"({"material": "glass", "shape": "polygon_decal", "center": [0, 0, 0], "u": [1, 0, 0],
                           "v": [0, 1, 0], "depth": [-1, 1], "polygon": [[0, 0], [1, 0]]})"),
              absl::StatusCode::kInvalidArgument, "regions[0].polygon: must be an array of 3 to 256 corners");
  ExpectError(SceneJson(R"({"material": "glass", "shape": "polygon_decal", "center": [0, 0, 0], "u": [1, 0, 0],
                           "v": [0, 1, 0], "depth": [-1, 1], "polygon": [[0, 0], [1, 1], [2, 2]]})"),
              absl::StatusCode::kInvalidArgument, "regions[0].polygon: encloses no area");
  ExpectError(SceneJson(R"({"material": "glass", "shape": "polygon_decal", "center": [0, 0, 0], "u": [1, 0, 0],
                           "v": [0, 1, 0], "depth": [-1, 1], "polygon": [[0, 0], [1, 0], [1]]})"),
              absl::StatusCode::kInvalidArgument, "regions[0].polygon[2]: must be an array of 2 numbers");
  ExpectError(SceneJson(R"({"material": "glass", "shape": "polygon_decal", "center": [0, 0, 0], "u": [1, 0, 0],
                           "v": [0, 1, 0], "depth": [1, -1], "polygon": [[0, 0], [1, 0], [0, 1]]})"),
              absl::StatusCode::kInvalidArgument, "regions[0].depth: is empty or inverted");
  ExpectError(SceneJson("", R"("units": "inch", )"), absl::StatusCode::kInvalidArgument, "unsupported 'inch'");
  ExpectError(R"({"name": "t", "mesh": "tet.obj", "default_material": "g",
                  "materials": {"g": {"mu": 0.1, "a1": 1.5, "a2": 0, "sigma": 0.1}}})",
              absl::StatusCode::kInvalidArgument, "not stationary");
  ExpectError(R"({"name": "t", "mesh": "tet.obj", "default_material": "g",
                  "materials": {"g": {"mu": -0.1, "a1": 0, "a2": 0, "sigma": 0.1}}})",
              absl::StatusCode::kInvalidArgument, "materials.g.mu");
  ExpectError(R"({"name": "t", "mesh": "tet.obj", "default_material": "g",
                  "materials": {"g": {"mu": 0.1, "a1": 0, "a2": 0, "sigma": "0.1"}}})",
              absl::StatusCode::kInvalidArgument, "materials.g.sigma: must be a number, not string");
  ExpectError(R"({"name": "t", "mesh": "missing.obj", "default_material": "g",
                  "materials": {"g": {"mu": 0.1, "a1": 0, "a2": 0, "sigma": 0.1}}})",
              absl::StatusCode::kNotFound, "missing.obj");
}

TEST_F(SceneFilesTest, RejectsAnInvalidMesh) {
  std::ofstream(dir_ / "bad.obj") << "v 0 0 0\nv 1 0 0\nf 1 2 3\n";
  ExpectError(R"({"name": "t", "mesh": "bad.obj", "default_material": "g",
                  "materials": {"g": {"mu": 0.1, "a1": 0, "a2": 0, "sigma": 0.1}}})",
              absl::StatusCode::kInvalidArgument, "test.json: mesh:");
}

TEST_F(SceneFilesTest, LoadSceneByDirectoryAndName) {
  std::ofstream(dir_ / "mine.json") << SceneJson("");
  auto scene = LoadScene(dir_, "mine");
  ASSERT_TRUE(scene.ok()) << scene.status();
  EXPECT_EQ(scene->source, (dir_ / "mine.json").string());
  EXPECT_EQ(LoadScene(dir_, "../etc/passwd").status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(LoadScene(dir_, "absent").status().code(), absl::StatusCode::kNotFound);
}

TEST_F(SceneFilesTest, SearchPathPrefersTheEnvironment) {
  std::ofstream(dir_ / "bottle.json") << SceneJson("");  // shadows the built-in bottle
  ASSERT_EQ(setenv("SURFMAP_SCENES", ("/nonexistent:" + dir_.string()).c_str(), 1), 0);
  const std::vector<fs::path> path = SceneSearchPath();
  ASSERT_GE(path.size(), 3u);
  EXPECT_EQ(path[0], fs::path("/nonexistent"));
  EXPECT_EQ(path[1], dir_);
  auto scene = LoadSceneByName("bottle");
  unsetenv("SURFMAP_SCENES");
  ASSERT_TRUE(scene.ok()) << scene.status();
  EXPECT_EQ(scene->name, "t");
  auto missing = LoadSceneByName("no_such_scene");
  EXPECT_EQ(missing.status().code(), absl::StatusCode::kNotFound);
  EXPECT_NE(missing.status().message().find("searched"), std::string::npos);
}

// Every region holds some of `points` (the first region containing a point
// takes it, as in the scene): none is hidden by an earlier one or placed off
// the object.
void ExpectEveryRegionHoldsPoints(const Scene& scene, const std::vector<Eigen::Vector3d>& points) {
  std::vector<int> count(scene.regions.size(), 0);
  for (const Eigen::Vector3d& p : points) {
    for (std::size_t r = 0; r < scene.regions.size(); ++r) {
      if (scene.regions[r].Contains(p)) {
        ++count[r];
        break;
      }
    }
  }
  for (std::size_t r = 0; r < count.size(); ++r) EXPECT_GT(count[r], 0) << "regions[" << r << "]";
}

TEST(BuiltInScenesTest, BottleHasGlassAndThreeSandpaperPatches) {
  auto scene = LoadSceneByName("bottle");
  ASSERT_TRUE(scene.ok()) << scene.status();
  EXPECT_EQ(scene->regions.size(), 3u);
  const int glass = scene->FindMaterial("glass");
  const int sand = scene->FindMaterial("sandpaper");
  ASSERT_GE(glass, 0);
  ASSERT_GE(sand, 0);
  EXPECT_DOUBLE_EQ(scene->materials[glass].mu, 0.13);
  EXPECT_DOUBLE_EQ(scene->materials[sand].mu, 0.5);
  EXPECT_EQ(scene->MaterialIndexAt({40, 0, 45}), sand);                // patch centres
  EXPECT_EQ(scene->MaterialIndexAt({-20, 34.64, 95}), sand);           // 120 deg
  EXPECT_EQ(scene->MaterialIndexAt({-20, -34.64, 65}), sand);          // 240 deg
  EXPECT_EQ(scene->MaterialIndexAt({-40, 0, 100}), glass);
  EXPECT_EQ(scene->MaterialIndexAt({40, 0, 100}), glass);
  EXPECT_EQ(scene->MaterialIndexAt({0, 0, 200}), glass);
}

TEST(BuiltInScenesTest, PlateHasRubberMasoniteAndWood) {
  auto scene = LoadSceneByName("plate");
  ASSERT_TRUE(scene.ok()) << scene.status();
  EXPECT_NEAR(scene->MaterialAt({-65, 0, 0}).mu, 0.305, 1e-12);
  EXPECT_NEAR(scene->MaterialAt({30, 0, 0}).a1, 1.61, 1e-12);
  EXPECT_NEAR(scene->MaterialAt({80, 60, 0}).mu, 0.42, 1e-12);
}

// The scenes beyond the paper's bottle and plate: every region is a feature
// comparable to or smaller than a 20 mm drag in at least one direction, and
// the control meshes were not built around the regions: control vertices lie
// near a boundary no more often than random points of the surface do.
TEST(BuiltInScenesTest, NewScenesHaveDragSizedFeaturesOffTheControlMesh) {
  constexpr double kNearMm = 1.0;
  for (const char* name : {"banded_vase", "strip_block", "dotted_egg", "torus_handle"}) {
    SCOPED_TRACE(name);
    auto scene = LoadSceneByName(name);
    ASSERT_TRUE(scene.ok()) << scene.status();
    ASSERT_GE(scene->regions.size(), 2u);
    SurfaceScoreOptions options;
    options.points = 4000;
    auto scorer = SurfaceScorer::Create(*scene, options);
    ASSERT_TRUE(scorer.ok()) << scorer.status();
    // Every region holds points of the true surface (none is hidden by an
    // earlier one or off the object).
    ExpectEveryRegionHoldsPoints(*scene, scorer->points());
    auto near_boundary = [&](const Eigen::Vector3d& p) {
      for (const Eigen::Vector3d& b : scorer->truth_boundary()) {
        if ((b - p).squaredNorm() < kNearMm * kNearMm) return true;
      }
      return false;
    };
    int points_near = 0;
    for (const Eigen::Vector3d& p : scorer->points()) points_near += near_boundary(p);
    auto surface = LoopSurface::Create(scene->mesh, 1);
    ASSERT_TRUE(surface.ok());
    const SurfaceLevel& level0 = (*surface)->level(0);
    int vertices_near = 0;
    for (const Eigen::Vector3d& p : level0.limit_positions) vertices_near += near_boundary(p);
    const double point_share = static_cast<double>(points_near) / scorer->points().size();
    const double vertex_share = static_cast<double>(vertices_near) / level0.limit_positions.size();
    // Twice the chance rate, plus two vertices of slack for small counts.
    EXPECT_LE(vertex_share, 2.0 * point_share + 2.0 / level0.limit_positions.size())
        << vertices_near << " of " << level0.limit_positions.size() << " control vertices within " << kNearMm
        << " mm of a boundary; " << 100.0 * point_share << " % of the surface is";
    // No boundary runs along a control edge: never both ends and the middle
    // (the edge's level-1 child) near a boundary.
    const SurfaceLevel& level1 = (*surface)->level(1);
    for (std::size_t e = 0; e < level0.edges.size(); ++e) {
      const auto [a, b] = level0.edges[e];
      EXPECT_FALSE(near_boundary(level0.limit_positions[a]) && near_boundary(level0.limit_positions[b]) &&
                   near_boundary(level1.limit_positions[level0.edge_child_vertex[e]]))
          << "control edge " << a << "-" << b << " lies along a boundary";
    }
  }
}

// Every scene shipped loads, including the dense scans (their truth is taken
// at the finest Loop level within the triangle limit, not refused), and each
// region holds points of its true surface: none is hidden by an earlier one
// or placed off the object.
TEST(BuiltInScenesTest, EverySceneLoadsAndEachRegionLiesOnItsSurface) {
  int scenes = 0;
  for (const auto& entry : std::filesystem::directory_iterator(SURFMAP_SOURCE_SCENES_DIR)) {
    if (entry.path().extension() != ".json") continue;
    SCOPED_TRACE(entry.path().filename().string());
    ++scenes;
    absl::StatusOr<Scene> scene = LoadSceneFiles(entry.path());
    ASSERT_TRUE(scene.ok()) << scene.status();
    EXPECT_EQ(scene->name, entry.path().stem().string());
    SurfaceScoreOptions options;
    options.points = 20000;  // a 6 mm dot on a 160 mm egg still draws ~40
    absl::StatusOr<SurfaceScorer> scorer = SurfaceScorer::Create(*scene, options);
    ASSERT_TRUE(scorer.ok()) << scorer.status();
    ExpectEveryRegionHoldsPoints(*scene, scorer->points());
  }
  EXPECT_GE(scenes, 16);
}

}  // namespace
}  // namespace surfmap
