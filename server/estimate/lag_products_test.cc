#include "server/estimate/lag_products.h"

#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>

namespace surfmap {
namespace {

using Kernel = void (*)(const double*, int, int, double*);

// Both paths against the textbook sum, over lengths and lag counts that hit
// every block size (8, 4, 1), short tails, lags = n, and a nonzero c on entry
// (the kernels add to it).
void ExpectEqualsTheDirectSum(Kernel kernel, const char* name) {
  std::mt19937_64 rng(2001);
  std::normal_distribution<double> normal(0.0, 1.0);
  for (int n : {1, 2, 3, 4, 5, 7, 8, 9, 11, 12, 13, 16, 31, 64, 161, 350}) {
    std::vector<double> x(n);
    for (double& v : x) v = normal(rng);
    for (int lags : {1, 2, 3, 4, 5, 8, 9, 12, 13, 16, 17, 40, 88, 175, 400}) {
      if (lags > n) continue;
      std::vector<double> c(lags, 0.5);
      kernel(x.data(), n, lags, c.data());
      for (int k = 0; k < lags; ++k) {
        double direct = 0.5;
        for (int i = 0; i + k < n; ++i) direct += x[i] * x[i + k];
        ASSERT_NEAR(c[k], direct, 1e-12 * (1.0 + std::abs(direct))) << name << ": n " << n << " lags " << lags
                                                                    << " lag " << k;
      }
    }
  }
}

TEST(LagProductsTest, PortablePathEqualsTheDirectSum) {
  ExpectEqualsTheDirectSum(&AddLagProductsPortable, "portable");
}

TEST(LagProductsTest, Avx2PathEqualsTheDirectSum) {
  if (!CpuHasAvx2Fma()) GTEST_SKIP() << "this CPU has no AVX2/FMA";
  ExpectEqualsTheDirectSum(&AddLagProductsAvx2, "avx2");
}

TEST(LagProductsTest, TheDispatchedPathAgreesWithThePortableOne) {
  std::mt19937_64 rng(7);
  std::normal_distribution<double> normal(0.0, 0.02);
  std::vector<double> x(350);
  for (double& v : x) v = normal(rng);
  std::vector<double> fast(176, 0.0), portable(176, 0.0);
  AddLagProducts(x.data(), 350, 176, fast.data());
  AddLagProductsPortable(x.data(), 350, 176, portable.data());
  for (int k = 0; k < 176; ++k) EXPECT_NEAR(fast[k], portable[k], 1e-15) << "lag " << k;
}

}  // namespace
}  // namespace surfmap
