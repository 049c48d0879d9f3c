#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include "clients/mapsim/map_evaluation.h"
#include "clients/mapsim/mapping_report.h"
#include "clients/mapsim/mapping_run.h"
#include "clients/rig/scene.h"
#include "server/map/testing/flat_grid_levels.h"

namespace surfmap::mapsim {
namespace {

// A 10 x 4 grid of 10 mm cells, x in [0, 100]: material 0 left of x = 45, 1 right.
struct SplitGrid {
  SurfaceLevel level = testing::MakeFlatGridLevels(10, 4, 10.0, 0).front();
  std::vector<int> truth;
  SplitGrid() {
    for (const auto& p : level.limit_positions) truth.push_back(p.x() < 45.0 ? 0 : 1);
  }
};

const std::vector<double> kMus = {0.13, 0.5};
const std::vector<std::string> kNames = {"glass", "sandpaper"};

TEST(EvaluateMapTest, PerfectMapHasNoErrorAnywhere) {
  SplitGrid g;
  std::vector<double> mu;
  for (int m : g.truth) mu.push_back(kMus[m]);
  auto e = EvaluateMap(g.level, mu, g.truth, kMus, kNames);
  ASSERT_TRUE(e.ok()) << e.status();
  EXPECT_EQ(e->vertices, 55);
  EXPECT_NEAR(e->mu_rmse, 0.0, 1e-12);
  EXPECT_DOUBLE_EQ(e->classification_accuracy, 1.0);
  EXPECT_EQ(e->truth_boundary_vertices, 10);  // columns x = 40 and 50, 5 rows each
  EXPECT_NEAR(e->boundary_error_mm, 0.0, 1e-12);
  EXPECT_NEAR(e->spurious_boundary_mm, 0.0, 1e-12);
  ASSERT_EQ(e->materials.size(), 2u);
  EXPECT_EQ(e->materials[0].vertices, 25);
  EXPECT_NEAR(e->materials[1].map_mu_mean, 0.5, 1e-12);
}

TEST(EvaluateMapTest, BoundaryShiftedOneCellCostsTenMillimetres) {
  SplitGrid g;
  std::vector<double> mu;
  // The map puts the boundary between x = 50 and 60 instead of 40 and 50.
  for (const auto& p : g.level.limit_positions) mu.push_back(p.x() < 55.0 ? 0.13 : 0.5);
  auto e = EvaluateMap(g.level, mu, g.truth, kMus, kNames);
  ASSERT_TRUE(e.ok()) << e.status();
  EXPECT_NEAR(e->classification_accuracy, 50.0 / 55.0, 1e-12);  // the x = 50 column is wrong
  EXPECT_NEAR(e->mu_rmse, std::sqrt(5.0 / 55.0) * 0.37, 1e-12);
  // Truth boundary columns 40 and 50, map's 50 and 60: half at 0, half at 10 mm.
  EXPECT_NEAR(e->boundary_error_mm, 5.0, 1e-12);
  EXPECT_NEAR(e->spurious_boundary_mm, 5.0, 1e-12);
}

TEST(EvaluateMapTest, OneMaterialMapHasNoBoundaryToMeasure) {
  SplitGrid g;
  std::vector<double> mu(g.truth.size(), 0.13);
  auto e = EvaluateMap(g.level, mu, g.truth, kMus, kNames);
  ASSERT_TRUE(e.ok()) << e.status();
  EXPECT_EQ(e->map_boundary_vertices, 0);
  EXPECT_TRUE(std::isnan(e->boundary_error_mm));
}

TEST(EvaluateMapTest, RejectsMismatchedSizesAndBadMaterials) {
  SplitGrid g;
  std::vector<double> mu(g.truth.size(), 0.13);
  std::vector<double> short_mu(3, 0.13);
  EXPECT_EQ(EvaluateMap(g.level, short_mu, g.truth, kMus, kNames).status().code(),
            absl::StatusCode::kInvalidArgument);
  std::vector<int> bad_truth = g.truth;
  bad_truth[7] = 2;
  auto e = EvaluateMap(g.level, mu, bad_truth, kMus, kNames);
  ASSERT_FALSE(e.ok());
  EXPECT_NE(std::string(e.status().message()).find("vertex 7"), std::string::npos) << e.status();
  mu[3] = std::nan("");
  EXPECT_FALSE(EvaluateMap(g.level, mu, g.truth, kMus, kNames).ok());
}

TEST(MappingRunTest, RejectsInvalidOptions) {
  MappingRunOptions o;
  o.mode = SamplingMode::kUncertainty;  // needs a budget
  std::string why;
  EXPECT_FALSE(o.IsValid(&why));
  EXPECT_NE(why.find("sample_budget"), std::string::npos) << why;
  o.mode = SamplingMode::kAdaptive;
  o.coarsest_level = 3;
  o.finest_level = 2;
  EXPECT_FALSE(o.IsValid(&why));
  EXPECT_NE(why.find("coarsest_level"), std::string::npos) << why;
}

// The whole loop on the plate (three materials, open boundary): the adaptive
// rule finds the strips with fewer samples than sampling the finest level
// uniformly, and classifies >= 90 % of the finest vertices right.
TEST(MappingRunTest, AdaptiveMapsThePlateWithFewerSamplesThanUniform) {
  auto scene = LoadSceneByName("plate");
  ASSERT_TRUE(scene.ok()) << scene.status();
  auto bench = MappingBench::Create(*std::move(scene), 2, 7);
  ASSERT_TRUE(bench.ok()) << bench.status();

  MappingRunOptions adaptive;
  adaptive.mode = SamplingMode::kAdaptive;
  adaptive.coarsest_level = 0;
  adaptive.finest_level = 2;
  adaptive.threshold = 1.0;
  adaptive.seed = 7;
  auto a = RunMapping(**bench, adaptive);
  ASSERT_TRUE(a.ok()) << a.status();

  MappingRunOptions uniform = adaptive;
  uniform.mode = SamplingMode::kUniformLevel;
  uniform.coarsest_level = 2;
  auto u = RunMapping(**bench, uniform);
  ASSERT_TRUE(u.ok()) << u.status();

  auto measured = [](const MappingRunResult& r) {
    int n = 0;
    for (const ProbeRecord& p : r.probes) n += p.measured;
    return n;
  };
  std::printf("%s", FormatComparisonTable({*a, *u}).c_str());
  EXPECT_GE(a->evaluation.classification_accuracy, 0.90);
  EXPECT_LT(measured(*a), measured(*u));
  EXPECT_GT(measured(*a), 99) << "the adaptive rule refined nothing beyond level 0";
  // The strips' own mu comes back from their samples.
  for (const MaterialEvaluation& m : a->evaluation.materials) {
    EXPECT_NEAR(m.map_mu_mean, m.truth_mu, 0.05) << m.name;
  }
  // Deterministic: the same run again gives the same map.
  auto again = RunMapping(**bench, adaptive);
  ASSERT_TRUE(again.ok());
  EXPECT_EQ(again->map_mu, a->map_mu);

  // The outputs render.
  auto png = RunPng(**bench, *a);
  ASSERT_TRUE(png.ok()) << png.status();
  EXPECT_EQ(png->substr(1, 3), "PNG");
  auto ply = RunPly(**bench, *a);
  ASSERT_TRUE(ply.ok()) << ply.status();
  EXPECT_EQ(ply->substr(0, 4), "ply\n");
}

}  // namespace
}  // namespace surfmap::mapsim
