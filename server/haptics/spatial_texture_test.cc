#include "server/haptics/spatial_texture.h"

#include <cmath>

#include <gtest/gtest.h>
#include "server/haptics/test_meshes.h"
#include "clients/sim/dragsim/material.h"
#include "server/estimate/roughness.h"

namespace surfmap::haptics {
namespace {

Eigen::VectorXd Series(const SpatialTexture& texture, const testing::TestMaterial& m, std::int64_t from, int n) {
  ArImpulse impulse;
  const double a[2] = {m.a1, m.a2};
  UpdateImpulse(a, 2, impulse);
  Eigen::VectorXd out(n);
  for (int i = 0; i < n; ++i) out[i] = texture.Roughness(from + i, m.sigma, impulse);
  return out;
}

// The resynthesised texture is the AR model: fitting it gives the model back.
// 40000 cells (4 m at 0.1 mm): the Burg estimates' standard errors are about
// sqrt((1 - a2^2) / n) ~ 0.005 for a1, a2; 0.03 allows 6 of them. sigma to 3%.
TEST(SpatialTextureTest, FitsBackToItsArModel) {
  const SpatialTexture texture(11);
  for (const auto& m : {testing::kRubber, testing::kMasonite}) {
    const Eigen::VectorXd r = Series(texture, m, 1000, 40000);
    ArFitOptions options;
    options.order = 2;
    absl::StatusOr<ArFit> fit = FitAutoregressive(r, options);
    ASSERT_TRUE(fit.ok()) << fit.status();
    EXPECT_NEAR(fit->a[0], m.a1, 0.03);
    EXPECT_NEAR(fit->a[1], m.a2, 0.03);
    EXPECT_NEAR(fit->sigma / m.sigma, 1.0, 0.03);
    // And its variance is the AR(2) process variance (dragsim's formula), to 5%
    // (masonite's strong correlation makes the sample variance noisier).
    const double var = ArProcessVariance(Material{m.mu, m.a1, m.a2, m.sigma});
    EXPECT_NEAR((r.array() - r.mean()).square().mean() / var, 1.0, 0.05);
  }
}

// A pure function of the cell: the same cells in any order give the same
// values, so stopping and going back feels the same texture.
TEST(SpatialTextureTest, ValueDependsOnlyOnTheCell) {
  const SpatialTexture texture(3);
  ArImpulse impulse;
  const double a[2] = {testing::kRubber.a1, testing::kRubber.a2};
  UpdateImpulse(a, 2, impulse);
  std::vector<double> forward;
  for (int k = 0; k < 200; ++k) forward.push_back(texture.Roughness(k, 0.1, impulse));
  for (int k = 199; k >= 0; --k) EXPECT_EQ(texture.Roughness(k, 0.1, impulse), forward[k]);
  // Another seed is another realisation.
  const SpatialTexture other(4);
  int same = 0;
  for (int k = 0; k < 200; ++k) same += other.Roughness(k, 0.1, impulse) == forward[k];
  EXPECT_EQ(same, 0);
}

// The truncated impulse response keeps all but kTailEnergy of the variance:
// compare its energy with the exact AR(2) variance gain.
TEST(SpatialTextureTest, ImpulseKeepsTheVariance) {
  for (const auto& m : {testing::kRubber, testing::kMasonite}) {
    ArImpulse impulse;
    const double a[2] = {m.a1, m.a2};
    UpdateImpulse(a, 2, impulse);
    const double exact = ArProcessVariance(Material{m.mu, m.a1, m.a2, 1.0});
    EXPECT_NEAR(impulse.variance_gain / exact, 1.0, 10 * kTailEnergy);
    EXPECT_LT(impulse.length, kMaxImpulseLength);
  }
}

TEST(SpatialTextureTest, StepUpMatchesTheEstimatorsConversion) {
  const std::vector<double> k = {0.8, -0.4, 0.3};
  double a[3];
  ReflectionToArInPlace(k.data(), 3, a);
  const std::vector<double> expected = ReflectionToAr(k);
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(a[i], expected[i], 1e-15);
}

}  // namespace
}  // namespace surfmap::haptics
