#include "server/estimate/normal_quantile.h"

#include <cmath>

#include <gtest/gtest.h>

namespace surfmap {
namespace {

TEST(NormalQuantileTest, MatchesTabulatedValues) {
  // Tabulated upper quantiles (to 1e-9).
  EXPECT_NEAR(NormalUpperQuantile(0.5), 0.0, 1e-12);
  EXPECT_NEAR(NormalUpperQuantile(0.025), 1.959963985, 1e-8);
  EXPECT_NEAR(NormalUpperQuantile(0.001), 3.090232306, 1e-8);
  EXPECT_NEAR(NormalUpperQuantile(1e-6), 4.753424309, 1e-8);
  EXPECT_NEAR(NormalUpperQuantile(0.975), -1.959963985, 1e-8);
}

TEST(NormalQuantileTest, InvertsTheTail) {
  for (double p : {1e-12, 1e-8, 3e-4, 0.01, 0.2, 0.5, 0.8, 0.99}) {
    EXPECT_NEAR(NormalUpperTail(NormalUpperQuantile(p)) / p, 1.0, 1e-12) << p;
  }
  EXPECT_TRUE(std::isnan(NormalUpperQuantile(std::nan(""))));
}

}  // namespace
}  // namespace surfmap
