#include "server/estimate/ar_autocorrelation.h"

#include <random>

#include <gtest/gtest.h>

namespace surfmap {
namespace {

// The blocked sums must equal the textbook definition for every length and
// lag count, including lags beyond the series and lengths shorter than a block.
TEST(PooledAutocovarianceTest, EqualsTheDirectSumForAnyLengthAndLag) {
  std::mt19937_64 rng(77);
  std::normal_distribution<double> normal(0.0, 1.0);
  for (int n1 : {1, 5, 8, 9, 17, 160}) {
    for (int n2 : {0, 3, 31, 161}) {
      std::vector<Eigen::VectorXd> series;
      for (int n : {n1, n2}) {
        Eigen::VectorXd x(n);
        for (int i = 0; i < n; ++i) x(i) = normal(rng);
        series.push_back(x);
      }
      for (int max_lag : {0, 1, 7, 8, 15, 40, 200}) {
        const Eigen::VectorXd c = PooledAutocovariance(series, max_lag);
        ASSERT_EQ(c.size(), max_lag + 1);
        for (int k = 0; k <= max_lag; ++k) {
          double direct = 0.0;
          for (const Eigen::VectorXd& x : series) {
            for (Eigen::Index i = 0; i + k < x.size(); ++i) direct += x(i) * x(i + k);
          }
          direct /= static_cast<double>(n1 + n2);
          EXPECT_NEAR(c(k), direct, 1e-12 * (1.0 + std::abs(direct))) << "n " << n1 << "+" << n2 << " lag " << k;
        }
      }
    }
  }
}

}  // namespace
}  // namespace surfmap
