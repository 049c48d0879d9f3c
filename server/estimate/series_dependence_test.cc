#include "server/estimate/series_dependence.h"

#include <gtest/gtest.h>
#include "server/estimate/roughness.h"

namespace surfmap {
namespace {

TEST(SeriesDependenceTest, WhiteNoiseIsNotInflated) {
  const Eigen::VectorXd x = SimulateRoughness({{0.0}, 1.0}, 4000, 1);
  const SeriesDependence d = EstimateSeriesDependence({x});
  EXPECT_TRUE(d.modelled);
  // From 4000 points the AR(2) coefficients carry a standard error of
  // ~0.016, so the inflation is within ~0.1 of 1.
  EXPECT_NEAR(d.mean_inflation, 1.0, 0.1);
}

TEST(SeriesDependenceTest, Ar1InflationMatchesTheClosedForm) {
  // AR(1) phi = 0.5: long-run / variance = (1 + phi) / (1 - phi) = 3; the
  // estimate of phi from 20000 points has se 0.006, i.e. ~5 % on 3.
  const Eigen::VectorXd x = SimulateRoughness({{0.5}, 1.0}, 20000, 2);
  EXPECT_NEAR(EstimateSeriesDependence({x}).mean_inflation, 3.0, 0.15);
}

TEST(SeriesDependenceTest, RubberTextureIsWorthFewIndependentPairs) {
  // Rubber's texture (a1 0.6, a2 0.25): Prod(1 - k^2) / (1 - a1 - a2)^2 =
  // (1 - 0.8^2)(1 - 0.25^2) / 0.15^2 = 15. From 20000 points within 10 %.
  const Eigen::VectorXd x = SimulateRoughness({{0.60, 0.25}, 0.022}, 20000, 3);
  EXPECT_NEAR(EstimateSeriesDependence({x}).mean_inflation, 15.0, 1.5);
}

TEST(SeriesDependenceTest, TooShortOrConstantIsIndependentData) {
  EXPECT_FALSE(EstimateSeriesDependence({Eigen::VectorXd::Ones(8)}).modelled);
  EXPECT_FALSE(EstimateSeriesDependence({Eigen::VectorXd::Constant(100, 2.0)}).modelled);
  EXPECT_EQ(EstimateSeriesDependence({}).mean_inflation, 1.0);
}

}  // namespace
}  // namespace surfmap
