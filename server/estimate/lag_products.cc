#include "server/estimate/lag_products.h"

#include <algorithm>

#include <Eigen/Core>

#if defined(__x86_64__) && defined(__GNUC__)
#include <immintrin.h>
#define SURFMAP_HAVE_AVX2_PATH 1
#endif

namespace surfmap {

void AddLagProductsPortable(const double* x, int n, int lags, double* c) {
  if (lags <= 0 || n <= 0) return;
  const Eigen::Map<const Eigen::VectorXd> series(x, n);
  if (lags == 1) {
    c[0] += series.squaredNorm();
    return;
  }
  // All lags as one matrix-vector product: column k of `shifted` is x moved
  // up by k (zeros past the end), a view of one padded copy (outer stride 1).
  // Eigen's GEMV works on several columns at once, ~1.5x faster than a dot
  // product per lag.
  Eigen::VectorXd padded = Eigen::VectorXd::Zero(n + lags);
  padded.head(n) = series;
  const Eigen::Map<const Eigen::MatrixXd, 0, Eigen::OuterStride<1>> shifted(padded.data(), n, lags,
                                                                           Eigen::OuterStride<1>(1));
  Eigen::Map<Eigen::VectorXd>(c, lags).noalias() += shifted.transpose() * series;
}

#ifdef SURFMAP_HAVE_AVX2_PATH
namespace {

// B lags k0 .. k0+B-1 with one 4-wide accumulator each: every load of x[i..]
// is shared by B fused multiply-adds, and B independent chains hide the FMA
// latency (B = 8 keeps 8 accumulators + operands within 16 registers).
template <int B>
__attribute__((target("avx2,fma"))) void LagBlock(const double* x, int n, int k0, double* c) {
  __m256d acc[B];
#pragma GCC unroll 8
  for (int j = 0; j < B; ++j) acc[j] = _mm256_setzero_pd();
  // i + 3 + k0 + B - 1 < n for every vector step of every lag in the block.
  const int common = n - k0 - (B - 1);
  int i = 0;
  for (; i + 4 <= common; i += 4) {
    const __m256d a = _mm256_loadu_pd(x + i);
#pragma GCC unroll 8
    for (int j = 0; j < B; ++j) acc[j] = _mm256_fmadd_pd(a, _mm256_loadu_pd(x + i + k0 + j), acc[j]);
  }
  for (int j = 0; j < B; ++j) {
    alignas(32) double lanes[4];
    _mm256_store_pd(lanes, acc[j]);
    double sum = (lanes[0] + lanes[1]) + (lanes[2] + lanes[3]);
    const int k = k0 + j;
    for (int t = i; t + k < n; ++t) sum += x[t] * x[t + k];
    c[k] += sum;
  }
}

}  // namespace

bool CpuHasAvx2Fma() {
  static const bool has = __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
  return has;
}

void AddLagProductsAvx2(const double* x, int n, int lags, double* c) {
  lags = std::min(lags, n);
  int k = 0;
  for (; k + 8 <= lags; k += 8) LagBlock<8>(x, n, k, c);
  for (; k + 4 <= lags; k += 4) LagBlock<4>(x, n, k, c);
  for (; k < lags; ++k) LagBlock<1>(x, n, k, c);
}
#else
bool CpuHasAvx2Fma() { return false; }
void AddLagProductsAvx2(const double* x, int n, int lags, double* c) { AddLagProductsPortable(x, n, lags, c); }
#endif

void AddLagProducts(const double* x, int n, int lags, double* c) {
  if (CpuHasAvx2Fma()) {
    AddLagProductsAvx2(x, n, lags, c);
  } else {
    AddLagProductsPortable(x, n, lags, c);
  }
}

}  // namespace surfmap
