// Every export parsed back with every attribute checked.
#include <cmath>

#include <gtest/gtest.h>
#include "server/haptics/test_meshes.h"
#include "server/haptics/texture_map_gltf.h"
#include "server/haptics/texture_map_ply.h"
#include "server/haptics/texture_model_json.h"

namespace surfmap::haptics {
namespace {

// A map with every attribute, unknowns included.
TextureMap FullMap() {
  TextureMap map = testing::Sphere(15.0, 8, 12);
  testing::PaintSplit(map, 2.0, testing::kRubber, testing::kMasonite);
  map.job_id = 42;
  map.level = 3;
  map.grid_step_mm = 0.05;
  for (size_t v = 0; v < map.positions.size(); ++v) {
    map.mu[v] += 1e-3 * static_cast<double>(v);  // distinct values per vertex
    map.mu_std[v] = 0.001 * (v % 7);
    map.boundary_probability[v] = 0.01 * (v % 50);
  }
  map.mu[3] = std::nan("");  // unknown
  map.mu_std[3] = std::nan("");
  map.region[3] = -1;
  return map;
}

void ExpectSame(double got, double want, double tol, const std::string& what) {
  if (std::isnan(want)) {
    EXPECT_TRUE(std::isnan(got)) << what;
  } else {
    EXPECT_NEAR(got, want, tol) << what;
  }
}

void ExpectSameMap(const TextureMap& got, const TextureMap& want, double tol, double position_tol) {
  EXPECT_EQ(got.job_id, want.job_id);
  EXPECT_EQ(got.level, want.level);
  EXPECT_DOUBLE_EQ(got.grid_step_mm, want.grid_step_mm);
  ASSERT_EQ(got.vertex_count(), want.vertex_count());
  ASSERT_EQ(got.triangles, want.triangles);
  ASSERT_EQ(got.ar_order, want.ar_order);
  ASSERT_EQ(got.normals.size(), want.normals.size());
  ASSERT_EQ(got.sigma.size(), want.sigma.size());
  ASSERT_EQ(got.region, want.region);
  ASSERT_EQ(got.boundary_probability.size(), want.boundary_probability.size());
  for (int v = 0; v < want.vertex_count(); ++v) {
    const std::string at = "vertex " + std::to_string(v);
    EXPECT_NEAR((got.positions[v] - want.positions[v]).norm(), 0.0, position_tol) << at;
    EXPECT_NEAR((got.normals[v] - want.normals[v]).norm(), 0.0, tol) << at;
    ExpectSame(got.mu[v], want.mu[v], tol, "mu " + at);
    ExpectSame(got.mu_std[v], want.mu_std[v], tol, "mu_std " + at);
    ExpectSame(got.sigma[v], want.sigma[v], tol, "sigma " + at);
    ExpectSame(got.a1[v], want.a1[v], tol, "a1 " + at);
    ExpectSame(got.a2[v], want.a2[v], tol, "a2 " + at);
    for (int j = 0; j < want.ar_order; ++j) ExpectSame(got.ReflectionAt(v, j), want.ReflectionAt(v, j), tol, "k " + at);
    ExpectSame(got.boundary_probability[v], want.boundary_probability[v], tol, "boundary_probability " + at);
  }
}

// PLY: 17 significant digits read back bit for bit.
TEST(ExportsTest, PlyRoundTripsEveryAttributeExactly) {
  const TextureMap map = FullMap();
  absl::StatusOr<std::string> ply = WriteTexturePly(map);
  ASSERT_TRUE(ply.ok()) << ply.status();
  EXPECT_NE(ply->find("property double boundary_probability"), std::string::npos);
  EXPECT_NE(ply->find("property double k2"), std::string::npos);
  absl::StatusOr<TextureMap> back = ReadTexturePly(*ply, "map.ply");
  ASSERT_TRUE(back.ok()) << back.status();
  ExpectSameMap(*back, map, 0.0, 0.0);
}

TEST(ExportsTest, PlyReaderNamesTheBadLine) {
  std::string ply = *WriteTexturePly(FullMap());
  ply.replace(ply.find("end_header\n") + 11, 1, "x");  // corrupt the first vertex's first field
  absl::StatusOr<TextureMap> back = ReadTexturePly(ply, "bad.ply");
  ASSERT_FALSE(back.ok());
  EXPECT_NE(std::string(back.status().message()).find("bad.ply:"), std::string::npos) << back.status();
}

// glTF and GLB: floats (relative 6e-8) and positions in metres (so 1e-5 mm
// on a 15 mm sphere after the mm -> m -> mm trip); unknowns round-trip as NaN.
TEST(ExportsTest, GltfAndGlbRoundTripEveryAttribute) {
  const TextureMap map = FullMap();
  for (bool binary : {false, true}) {
    absl::StatusOr<std::string> bytes = WriteTextureGltf(map, binary);
    ASSERT_TRUE(bytes.ok()) << bytes.status();
    EXPECT_EQ(bytes->substr(0, 4) == "glTF", binary);
    absl::StatusOr<TextureMap> back = ReadTextureGltf(*bytes, binary ? "map.glb" : "map.gltf");
    ASSERT_TRUE(back.ok()) << back.status();
    ExpectSameMap(*back, map, 2e-7, 1e-5);
    ASSERT_EQ(back->regions.size(), 2u);
    EXPECT_DOUBLE_EQ(back->regions[1].mu, testing::kMasonite.mu);
    EXPECT_DOUBLE_EQ(back->regions[1].ar_coefficients[0], testing::kMasonite.a1);
  }
}

TEST(ExportsTest, TextureJsonRoundTripsTheRegions) {
  const TextureMap map = FullMap();
  absl::StatusOr<nlohmann::json> json = TextureModelToJson(map);
  ASSERT_TRUE(json.ok());
  // Through text, as a file would go.
  const nlohmann::json parsed = nlohmann::json::parse(json->dump());
  absl::StatusOr<TextureModel> model = TextureModelFromJson(parsed, "model.json");
  ASSERT_TRUE(model.ok()) << model.status();
  EXPECT_EQ(model->job_id, 42);
  EXPECT_EQ(model->level, 3);
  EXPECT_EQ(model->vertex_count, map.vertex_count());
  EXPECT_DOUBLE_EQ(model->grid_step_mm, 0.05);
  ASSERT_EQ(model->regions.size(), map.regions.size());
  for (size_t i = 0; i < map.regions.size(); ++i) {
    const TextureRegion& a = model->regions[i];
    const TextureRegion& b = map.regions[i];
    EXPECT_EQ(a.region, b.region);
    EXPECT_DOUBLE_EQ(a.mu, b.mu);
    EXPECT_DOUBLE_EQ(a.mu_se, b.mu_se);
    EXPECT_DOUBLE_EQ(a.mu_spread, b.mu_spread);
    EXPECT_EQ(a.piece_count, b.piece_count);
    EXPECT_EQ(a.roughness_piece_count, b.roughness_piece_count);
    EXPECT_EQ(a.ar_coefficients, b.ar_coefficients);
    EXPECT_EQ(a.reflection, b.reflection);
    EXPECT_DOUBLE_EQ(a.sigma, b.sigma);
    EXPECT_DOUBLE_EQ(a.area_mm2, b.area_mm2);
  }
  // Derived amplitude: masonite's AR(2) process std, sigma * sqrt(gain) =
  // 0.16 * sqrt(15.99) = 0.6397 N (gamma0 = sigma^2 (1-a2) / ((1+a2)((1-a2)^2 - a1^2))).
  EXPECT_NEAR((*json)["regions"][1]["roughness_std_n"].get<double>(), 0.6397, 1e-3);
  EXPECT_EQ((*json)["units"]["sigma"], "N");
  EXPECT_EQ((*json)["unassigned_vertex_count"], 1);
  EXPECT_FALSE(TextureModelFromJson(nlohmann::json{{"format", "x"}}, "m").ok());
}

}  // namespace
}  // namespace surfmap::haptics
