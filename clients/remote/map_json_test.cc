#include "clients/remote/map_json.h"

#include <cmath>
#include <limits>

#include <gtest/gtest.h>

namespace surfmap::cli {
namespace {

namespace pb = ::surfmap::v1;

pb::Vec3 V(double x, double y, double z) {
  pb::Vec3 v;
  v.set_x(x);
  v.set_y(y);
  v.set_z(z);
  return v;
}

// A two-triangle square with one unknown vertex and one sample.
pb::GetMapResponse SquareMap() {
  pb::GetMapResponse r;
  pb::MapLevel* m = r.mutable_map();
  m->set_job_id(7);
  m->set_level(1);
  m->set_vertex_count(4);
  for (double mu : {0.1, 0.2, std::numeric_limits<double>::quiet_NaN(), 0.5}) m->add_mu(mu);
  for (double u : {0.01, 0.02, 0.5, 0.05}) m->add_mu_uncertainty(u);
  pb::Sample* s = m->add_samples();
  s->set_trace_id(11);
  s->mutable_site()->set_level(0);
  s->mutable_site()->set_vertex(3);
  *s->mutable_position() = V(1, 1, 0);
  *s->mutable_drag_direction() = V(1, 0, 0);
  s->set_segment_length_mm(20);
  s->mutable_fit()->mutable_friction()->set_mu(0.5);
  s->mutable_fit()->mutable_friction()->set_mu_std(0.02);
  pb::GetMeshResponse* mesh = r.mutable_mesh();
  for (auto p : {V(0, 0, 0), V(1, 0, 0), V(0, 1, 0), V(1, 1, 0)}) {
    *mesh->add_positions() = p;
    *mesh->add_normals() = V(0, 0, 1);
  }
  for (int i : {0, 1, 3, 0, 3, 2}) mesh->add_triangle_indices(i);
  return r;
}

TEST(MapJsonTest, WritesVerticesSamplesAndSummary) {
  const nlohmann::json j = MapToJson(SquareMap(), nullptr);
  EXPECT_EQ(j["format"], "surfmap.map.v1");
  EXPECT_EQ(j["job_id"], 7);
  EXPECT_EQ(j["vertices"]["mu"].size(), 4u);
  EXPECT_TRUE(j["vertices"]["mu"][2].is_null());  // NaN -> null
  EXPECT_EQ(j["triangles"].size(), 2u);
  EXPECT_EQ(j["triangles"][1], nlohmann::json({0, 3, 2}));
  EXPECT_EQ(j["samples"][0]["fit"]["friction"]["mu"], 0.5);
  EXPECT_EQ(j["summary"]["samples"], 1);
  EXPECT_EQ(j["summary"]["samples_per_level"]["0"], 1);
  EXPECT_NEAR(j["summary"]["mu_mean"].get<double>(), (0.1 + 0.2 + 0.5) / 3, 1e-12);
  EXPECT_EQ(j["summary"]["vertices_with_mu"], 3);
  EXPECT_FALSE(j.contains("job"));
}

TEST(MapJsonTest, RoundTripsThroughText) {
  const std::string text = MapToJson(SquareMap(), nullptr).dump();
  absl::StatusOr<MapDocument> doc = MapDocumentFromJson(nlohmann::json::parse(text), "m.json");
  ASSERT_TRUE(doc.ok()) << doc.status();
  EXPECT_EQ(doc->job_id, 7);
  EXPECT_EQ(doc->level, 1);
  ASSERT_EQ(doc->mu.size(), 4u);
  EXPECT_DOUBLE_EQ(doc->mu[1], 0.2);
  EXPECT_TRUE(std::isnan(doc->mu[2]));
  ASSERT_EQ(doc->positions.size(), 4u);
  EXPECT_DOUBLE_EQ(doc->positions[3][1], 1.0);
  ASSERT_EQ(doc->triangles.size(), 2u);
  ASSERT_EQ(doc->samples.size(), 1u);
  EXPECT_EQ(doc->samples[0].trace_id, 11);
  EXPECT_EQ(doc->samples[0].site_vertex, 3);
  EXPECT_DOUBLE_EQ(doc->samples[0].mu, 0.5);
  EXPECT_DOUBLE_EQ(doc->samples[0].segment_length_mm, 20.0);
}

TEST(MapJsonTest, RejectsOtherFilesNamingThePath) {
  absl::StatusOr<MapDocument> doc = MapDocumentFromJson(nlohmann::json{{"a", 1}}, "x.json");
  ASSERT_FALSE(doc.ok());
  EXPECT_EQ(doc.status().message(), "x.json: format: must be \"surfmap.map.v1\" (not a surfmap map file?)");

  nlohmann::json j = MapToJson(SquareMap(), nullptr);
  j["vertices"]["mu"].erase(0);
  doc = MapDocumentFromJson(j, "m.json");
  ASSERT_FALSE(doc.ok());
  EXPECT_EQ(doc.status().message(), "m.json: vertices.mu: has 3 values, vertex_count is 4");

  j = MapToJson(SquareMap(), nullptr);
  j["vertices"]["position"][2] = "x";
  doc = MapDocumentFromJson(j, "m.json");
  ASSERT_FALSE(doc.ok());
  EXPECT_EQ(doc.status().message(), "m.json: vertices.position[2]: must be an array of 3 numbers");
}

}  // namespace
}  // namespace surfmap::cli
