// Roots and spectrum of an AR model's characteristic polynomial
// z^p - a1 z^(p-1) - ... - ap (see roughness.h for the model convention).
#pragma once

#include <complex>
#include <optional>
#include <vector>

namespace surfmap {

// All p roots (with multiplicity), from the eigenvalues of the companion
// matrix; empty for an empty `a`. Order unspecified.
std::vector<std::complex<double>> ArCharacteristicRoots(const std::vector<double>& a);

// Largest root modulus; 0 for an empty `a`. The model is stationary iff < 1.
double ArLargestRootModulus(const std::vector<double>& a);

// Dominant spatial wavelength in grid steps: 2 pi / |arg z| for the
// largest-modulus root z. None when that root is real (no oscillation) or when
// the power spectrum sigma^2 / |1 - sum a_j e^(-i j w)|^2 peaks at w = 0 (a
// complex pair too weak to make a spectral peak). For AR(2) with complex roots
// this is 2 pi / acos(a1 / (2 sqrt(-a2))).
std::optional<double> ArDominantWavelengthSteps(const std::vector<double>& a);

}  // namespace surfmap
