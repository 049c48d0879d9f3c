#include "server/map/friction_map.h"

#include <cmath>
#include <random>

#include <gtest/gtest.h>
#include "server/map/testing/flat_grid_levels.h"

namespace surfmap {
namespace {

using testing::MakeFlatGridLevels;

TextureParams Texture(double mu, double mu_std = 0.0, std::vector<double> k = {}, double sigma = 0.0) {
  TextureParams p;
  p.mu = mu;
  p.mu_std = mu_std;
  p.reflection = std::move(k);
  p.sigma = sigma;
  return p;
}

bool OnBoundary(const Eigen::Vector3d& p, double x0, double x1, double y0, double y1) {
  const double eps = 1e-9;
  return std::abs(p.x() - x0) < eps || std::abs(p.x() - x1) < eps || std::abs(p.y() - y0) < eps ||
         std::abs(p.y() - y1) < eps;
}

class LinearFieldTest : public ::testing::TestWithParam<LaplacianWeights> {};

TEST_P(LinearFieldTest, HarmonicInterpolationReproducesLinearFieldFromBoundarySamples) {
  const auto levels = MakeFlatGridLevels(8, 6, 5.0, 1);  // 40 x 30 mm, finest 17 x 13 vertices
  const SurfaceLevel& finest = levels.back();
  auto truth = [](const Eigen::Vector3d& p) { return 0.2 + 0.004 * p.x() - 0.003 * p.y(); };
  std::vector<MapSample> samples;
  int interior = 0;
  for (int v = 0; v < static_cast<int>(finest.positions.size()); ++v) {
    const auto& p = finest.limit_positions[v];
    if (OnBoundary(p, 0, 40, 0, 30)) {
      samples.push_back({v, Texture(truth(p))});
    } else {
      ++interior;
    }
  }
  ASSERT_GT(interior, 100);
  FrictionMapOptions options;
  options.weights = GetParam();
  auto map = FrictionMap::Create(finest, options);
  ASSERT_TRUE(map.ok()) << map.status();
  ASSERT_TRUE(map->SetSamples(samples).ok());
  for (int v = 0; v < map->vertex_count(); ++v) {
    EXPECT_NEAR(map->mu()[v], truth(finest.limit_positions[v]), 1e-8) << "vertex " << v;
  }
}

INSTANTIATE_TEST_SUITE_P(Weights, LinearFieldTest,
                         ::testing::Values(LaplacianWeights::kCotangent, LaplacianWeights::kCotangentClamped,
                                           LaplacianWeights::kUniform),
                         [](const auto& info) {
                           switch (info.param) {
                             case LaplacianWeights::kCotangent:
                               return std::string("cotangent");
                             case LaplacianWeights::kCotangentClamped:
                               return std::string("cotangent_clamped");
                             case LaplacianWeights::kUniform:
                               return std::string("uniform");
                           }
                           return std::string("unknown");
                         });

TEST(FrictionMapTest, LinearFieldOnIrregularFlatMeshWithCotangentWeights) {
  // Jitter the interior vertices: uniform weights lose linear precision, the
  // cotangent Laplacian keeps it on any flat triangulation.
  auto levels = MakeFlatGridLevels(6, 6, 10.0, 0);
  SurfaceLevel& level = levels[0];
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> jitter(-2.0, 2.0);
  for (auto& p : level.positions) {
    if (!OnBoundary(p, 0, 60, 0, 60)) p += Eigen::Vector3d(jitter(rng), jitter(rng), 0.0);
  }
  level.limit_positions = level.positions;
  auto truth = [](const Eigen::Vector3d& p) { return 0.1 + 0.005 * p.x() + 0.002 * p.y(); };
  std::vector<MapSample> samples;
  for (int v = 0; v < static_cast<int>(level.positions.size()); ++v) {
    if (OnBoundary(level.positions[v], 0, 60, 0, 60)) samples.push_back({v, Texture(truth(level.positions[v]))});
  }
  for (auto weights : {LaplacianWeights::kCotangent, LaplacianWeights::kCotangentClamped,
                       LaplacianWeights::kUniform}) {
    FrictionMapOptions options;
    options.weights = weights;
    auto map = FrictionMap::Create(level, options);
    ASSERT_TRUE(map.ok());
    ASSERT_TRUE(map->SetSamples(samples).ok());
    double worst = 0.0;
    for (int v = 0; v < map->vertex_count(); ++v) {
      worst = std::max(worst, std::abs(map->mu()[v] - truth(level.positions[v])));
    }
    if (weights == LaplacianWeights::kCotangent) {
      EXPECT_LT(worst, 1e-8);
    } else {
      EXPECT_GT(worst, 1e-4);  // the uniform and clamped Laplacians are not linear-precise here
    }
  }
}

TEST(FrictionMapTest, ConstantFieldStaysConstantIncludingRoughness) {
  const auto levels = MakeFlatGridLevels(5, 5, 4.0, 2);
  const SurfaceLevel& finest = levels.back();
  std::mt19937_64 rng(11);
  std::uniform_int_distribution<int> pick(0, static_cast<int>(finest.positions.size()) - 1);
  std::vector<MapSample> samples;
  std::vector<char> used(finest.positions.size(), 0);
  while (samples.size() < 12) {
    const int v = pick(rng);
    if (used[v]) continue;
    used[v] = 1;
    samples.push_back({v, Texture(0.31, 0.01, {0.5, -0.2}, 0.12)});
  }
  auto map = FrictionMap::Create(finest);
  ASSERT_TRUE(map.ok());
  ASSERT_TRUE(map->SetSamples(samples).ok());
  ASSERT_EQ(map->roughness_order(), 2);
  for (int v = 0; v < map->vertex_count(); ++v) {
    const MapValue value = map->VertexValue(v);
    EXPECT_NEAR(value.mu, 0.31, 1e-12);
    ASSERT_TRUE(value.has_roughness);
    EXPECT_NEAR(value.reflection[0], 0.5, 1e-12);
    EXPECT_NEAR(value.reflection[1], -0.2, 1e-12);
    EXPECT_NEAR(value.sigma, 0.12, 1e-12);
  }
}

TEST(FrictionMapTest, UncertaintyIsTheSampleNoiseAtSamplesAndGrowsAwayFromThem) {
  const auto levels = MakeFlatGridLevels(20, 2, 5.0, 0);  // a 100 x 10 mm strip
  const SurfaceLevel& level = levels[0];
  // Two samples at x = 0 and x = 100 on the middle row (y = 5).
  const int row = 1, stride = 21;
  const int left = row * stride + 0, right = row * stride + 20;
  auto map = FrictionMap::Create(level);
  ASSERT_TRUE(map.ok());
  ASSERT_TRUE(map->SetSamples({{left, Texture(0.13, 0.004)}, {right, Texture(0.5, 0.01)}}).ok());
  EXPECT_NEAR(map->mu_std()[left], 0.004, 1e-12);
  EXPECT_NEAR(map->mu_std()[right], 0.01, 1e-12);
  // Along the row: strictly growing up to the middle, then falling to the right sample.
  for (int i = 1; i <= 10; ++i) {
    EXPECT_GT(map->mu_std()[row * stride + i], map->mu_std()[row * stride + i - 1]) << "i=" << i;
  }
  for (int i = 11; i <= 20; ++i) {
    EXPECT_LT(map->mu_std()[row * stride + i], map->mu_std()[row * stride + i - 1]) << "i=" << i;
  }
  // Values stay within the measured range (maximum principle).
  for (double mu : map->mu()) {
    EXPECT_GE(mu, 0.13 - 1e-12);
    EXPECT_LE(mu, 0.5 + 1e-12);
  }
}

TEST(FrictionMapTest, PendingSitesLowerUncertaintyButNotValues) {
  const auto levels = MakeFlatGridLevels(20, 2, 5.0, 0);
  const SurfaceLevel& level = levels[0];
  auto map = FrictionMap::Create(level);
  ASSERT_TRUE(map.ok());
  ASSERT_TRUE(map->SetSamples({{21, Texture(0.13, 0.004)}, {41, Texture(0.5, 0.004)}}).ok());
  const auto mu_before = map->mu();
  const double std_before = map->mu_std()[31];
  ASSERT_TRUE(map->SetPendingVertices({31}).ok());
  EXPECT_EQ(map->mu(), mu_before);
  EXPECT_LT(map->mu_std()[31], 0.5 * std_before);
  EXPECT_NEAR(map->distance_to_sample_mm()[31], 0.0, 1e-12);
  EXPECT_FALSE(map->SetPendingVertices({-1}).ok());
}

TEST(FrictionMapTest, RoughnessInterpolatesInLogSigmaAndStaysStationary) {
  const auto levels = MakeFlatGridLevels(2, 1, 10.0, 0);  // 3 x 2 vertices
  const SurfaceLevel& level = levels[0];
  auto map = FrictionMap::Create(level);  // cotangent: linear in x between the columns
  ASSERT_TRUE(map.ok());
  // Left column rough with sigma 0.1, right column sigma 0.4; the middle column
  // is halfway: log sigma halfway, i.e. sigma = 0.2.
  const auto a = Texture(0.2, 0.0, {0.95, -0.9}, 0.1), b = Texture(0.4, 0.0, {-0.95, 0.9}, 0.4);
  ASSERT_TRUE(map->SetSamples({{0, a}, {3, a}, {2, b}, {5, b}}).ok());
  for (int v : {1, 4}) {
    const MapValue value = map->VertexValue(v);
    EXPECT_NEAR(value.mu, 0.3, 1e-8);
    EXPECT_NEAR(value.sigma, 0.2, 1e-8);
    EXPECT_NEAR(value.reflection[0], 0.0, 1e-8);
    for (double k : value.reflection) EXPECT_LT(std::abs(k), 1.0);
  }
}

TEST(FrictionMapTest, SamplesWithoutRoughnessAreLeftOutOfTheRoughnessFields) {
  const auto levels = MakeFlatGridLevels(4, 1, 10.0, 0);
  auto map = FrictionMap::Create(levels[0]);
  ASSERT_TRUE(map.ok());
  ASSERT_TRUE(map->SetSamples({{0, Texture(0.2, 0.0, {0.3}, 0.2)}, {4, Texture(0.4)}}).ok());
  EXPECT_EQ(map->roughness_order(), 1);
  for (int v = 0; v < map->vertex_count(); ++v) {
    EXPECT_NEAR(map->VertexValue(v).sigma, 0.2, 1e-12);  // the only rough sample
  }
  EXPECT_NEAR(map->mu()[4], 0.4, 1e-12);
  ASSERT_TRUE(map->SetSamples({{0, Texture(0.2)}}).ok());
  EXPECT_FALSE(map->VertexValue(3).has_roughness);
}

TEST(FrictionMapTest, ValueAtBlendsTheTriangleVertices) {
  const auto levels = MakeFlatGridLevels(4, 4, 10.0, 1);
  const SurfaceLevel& finest = levels.back();
  std::vector<MapSample> samples;
  for (int v = 0; v < static_cast<int>(finest.positions.size()); v += 3) {
    samples.push_back({v, Texture(0.1 + 0.001 * v, 0.0, {0.2}, 0.1 + 0.0001 * v)});
  }
  auto map = FrictionMap::Create(finest);
  ASSERT_TRUE(map.ok());
  ASSERT_TRUE(map->SetSamples(samples).ok());
  SurfacePoint point;
  point.triangle = 17;
  const auto& t = finest.triangles[17];
  point.barycentric = Eigen::Vector3d(0.2, 0.3, 0.5);
  auto value = map->ValueAt(point);
  ASSERT_TRUE(value.ok()) << value.status();
  EXPECT_NEAR(value->mu, 0.2 * map->mu()[t[0]] + 0.3 * map->mu()[t[1]] + 0.5 * map->mu()[t[2]], 1e-12);
  point.barycentric = Eigen::Vector3d(0, 1, 0);
  value = map->ValueAt(point);
  ASSERT_TRUE(value.ok());
  EXPECT_NEAR(value->mu, map->mu()[t[1]], 1e-15);
  EXPECT_NEAR(value->sigma, map->VertexValue(t[1]).sigma, 1e-12);
  point.triangle = static_cast<int>(finest.triangles.size());
  EXPECT_EQ(map->ValueAt(point).status().code(), absl::StatusCode::kInvalidArgument);
}

TEST(FrictionMapTest, RejectsBadSamplesAndKeepsThePreviousState) {
  const auto levels = MakeFlatGridLevels(3, 3, 10.0, 0);
  auto map = FrictionMap::Create(levels[0]);
  ASSERT_TRUE(map.ok());
  SurfacePoint point;
  point.triangle = 0;
  EXPECT_EQ(map->ValueAt(point).status().code(), absl::StatusCode::kFailedPrecondition);
  EXPECT_FALSE(map->SetSamples({}).ok());
  ASSERT_TRUE(map->SetSamples({{0, Texture(0.2)}}).ok());
  auto status = map->SetSamples({{1, Texture(0.3)}, {1, Texture(0.4)}});
  EXPECT_EQ(status.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(status.message().find("sample 1"), std::string::npos) << status;
  EXPECT_FALSE(map->SetSamples({{99, Texture(0.3)}}).ok());
  EXPECT_FALSE(map->SetSamples({{1, Texture(NAN)}}).ok());
  EXPECT_FALSE(map->SetSamples({{1, Texture(0.3, 0.0, {1.0}, 0.1)}}).ok());
  EXPECT_FALSE(map->SetSamples({{1, Texture(0.3, -1.0)}}).ok());
  EXPECT_NEAR(map->mu()[5], 0.2, 1e-12);  // unchanged
  EXPECT_FALSE(FrictionMap::Create(levels[0], {.correlation_length_mm = -1}).ok());
  EXPECT_FALSE(FrictionMap::Create(SurfaceLevel{}).ok());
}

TEST(FrictionMapTest, ComponentWithoutSamplesGetsTheMeanAndThePriorUncertainty) {
  // Two separate plates in one level.
  auto a = testing::MakeFlatGrid(2, 2, 10.0);
  const auto b = testing::MakeFlatGrid(2, 2, 10.0, 100.0);
  const int offset = static_cast<int>(a.positions.size());
  for (const auto& p : b.positions) a.positions.push_back(p);
  for (const auto& t : b.triangles) a.triangles.push_back({t[0] + offset, t[1] + offset, t[2] + offset});
  a.limit_positions = a.positions;
  a.limit_normals.assign(a.positions.size(), Eigen::Vector3d::UnitZ());
  testing::FillEdgesAndNeighbors(a);
  auto map = FrictionMap::Create(a);
  ASSERT_TRUE(map.ok());
  ASSERT_TRUE(map->SetSamples({{0, Texture(0.1)}, {8, Texture(0.3)}}).ok());
  EXPECT_NEAR(map->mu()[offset + 4], 0.2, 1e-12);
  EXPECT_NEAR(map->mu_std()[offset + 4], map->prior_mu_std(), 1e-12);
}

}  // namespace
}  // namespace surfmap
