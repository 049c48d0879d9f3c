// Quantiles of the standard normal distribution, for the critical values of
// the significance tests (change points in a drag, texture differences on the
// map).
#pragma once

namespace surfmap {

// z with P(Z > z) = upper_tail for Z ~ N(0, 1): Acklam's rational
// approximation refined by one Halley step on std::erfc (relative error
// ~1e-15 over the whole range). upper_tail is clamped into [1e-300, 1 - 1e-16];
// NaN gives NaN.
double NormalUpperQuantile(double upper_tail);

// P(Z > z) for Z ~ N(0, 1).
double NormalUpperTail(double z);

}  // namespace surfmap
