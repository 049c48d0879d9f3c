#include "clients/haptics/realism/realism.h"

#include <random>

#include <gtest/gtest.h>

namespace surfmap::haptics {
namespace {

// The KS test behind the realism table: same distribution -> small D, large
// p; a shifted one -> D near the shift's CDF gap, tiny p. 2000 seeded normals
// each: D's null spread is ~ 1.36 sqrt(2 / 2000) = 0.043 at 5%.
TEST(KolmogorovSmirnovTest, SeparatesShiftedFromSame) {
  std::mt19937_64 rng(9);
  std::normal_distribution<double> normal(0.0, 1.0);
  std::vector<double> a, b, c;
  for (int i = 0; i < 2000; ++i) {
    a.push_back(normal(rng));
    b.push_back(normal(rng));
    c.push_back(normal(rng) + 1.0);
  }
  double d = 0, p = 0;
  KolmogorovSmirnov(a, b, &d, &p);
  EXPECT_LT(d, 0.043);
  EXPECT_GT(p, 0.05);
  KolmogorovSmirnov(a, c, &d, &p);
  // The largest CDF gap of N(0,1) vs N(1,1) is 2 Phi(0.5) - 1 = 0.383.
  EXPECT_NEAR(d, 0.383, 0.05);
  EXPECT_LT(p, 1e-6);
  KolmogorovSmirnov(a, a, &d, &p);
  EXPECT_EQ(d, 0.0);
  EXPECT_EQ(p, 1.0);
}

}  // namespace
}  // namespace surfmap::haptics
