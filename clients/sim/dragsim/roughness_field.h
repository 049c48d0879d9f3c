// A roughness field on a drag path: one realisation of the (possibly
// region-dependent) AR(2) process on the path's arc-length grid, so the
// forward and the reverse pass feel the same texture at the same place.
#pragma once

#include <cstdint>
#include <vector>

#include "clients/sim/dragsim/drag_geometry.h"
#include "clients/sim/dragsim/material.h"

namespace surfmap {

// How the field is read between grid points.
enum class RoughnessInterpolation {
  // The value of the nearest grid point: a texture of 0.1 mm cells. A probe
  // sampling about once per cell at any offset sees the AR process itself.
  kNearest,
  // Linear between grid points: continuous, but a probe sampling between the
  // grid points sees a low-passed process. AR(2) models with a negative real
  // root (rubber: roots 0.88 and -0.28) put power at the grid's Nyquist
  // frequency, which no continuous texture reproduces at every sampling
  // offset: with 3% speed jitter a rubber fit then reads a1 ~0.85, a2 ~0.
  kLinear,
};

class RoughnessField {
 public:
  // Realises r(k), k = 0..length/step, with the material at grid point k:
  //   r(k) = a1 r(k-1) + a2 r(k-2) + sigma e(k),  e ~ N(0, 1) seeded.
  // A burn-in of 200 samples with the material at s = 0 comes first, so the
  // field is stationary from its start.
  RoughnessField(const GeometryPath& path, const MaterialField& material, double step_mm,
                 std::uint64_t seed,
                 RoughnessInterpolation interpolation = RoughnessInterpolation::kNearest);
  // The field at arc length s (clamped to the path), N.
  double At(double s) const;
  const std::vector<double>& values() const { return values_; }
  double step_mm() const { return step_mm_; }

 private:
  double step_mm_;
  RoughnessInterpolation interpolation_;
  std::vector<double> values_;
};

}  // namespace surfmap
