// Removal of a least-squares straight line over the sample index: how the
// force variation is detrended before an AR fit (force_variation.h), and how
// the bias correction's replicates are treated the same way
// (ar_bias_correction.h).
#pragma once

namespace surfmap {

// v[0..n) minus its least-squares line over k = 0..n-1 (n = 1: set to 0;
// n <= 0: nothing).
void RemoveLinearTrend(double* v, int n);

}  // namespace surfmap
