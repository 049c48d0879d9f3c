// The inner loop of the sample autocovariance: lagged products of one series,
// for all lags at once. It is half the time of a whole trace fit, so it has a
// hand-vectorised AVX2/FMA path chosen at run time (the build targets plain
// x86-64, so the compiler alone only uses SSE2), and a portable path.
#pragma once

namespace surfmap {

// c[k] += sum_{i=0}^{n-1-k} x[i] * x[i+k] for k = 0 .. lags-1 (lags <= n).
// Picks the AVX2 path when the CPU has AVX2 and FMA.
void AddLagProducts(const double* x, int n, int lags, double* c);

// The two paths, for tests that compare them.
void AddLagProductsPortable(const double* x, int n, int lags, double* c);
// Only callable when CpuHasAvx2Fma().
void AddLagProductsAvx2(const double* x, int n, int lags, double* c);
bool CpuHasAvx2Fma();

}  // namespace surfmap
