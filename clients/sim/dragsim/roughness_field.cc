#include "clients/sim/dragsim/roughness_field.h"

#include <algorithm>
#include <cmath>
#include <random>

namespace surfmap {

RoughnessField::RoughnessField(const GeometryPath& path, const MaterialField& material,
                               double step_mm, std::uint64_t seed,
                               RoughnessInterpolation interpolation)
    : step_mm_(step_mm), interpolation_(interpolation) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> gauss(0.0, 1.0);
  const int n = static_cast<int>(std::ceil(path.length_mm() / step_mm)) + 1;
  values_.resize(n);
  Eigen::Vector3d p, normal, tangent;
  path.At(0.0, &p, &normal, &tangent);
  const Material first = material(p);
  double r1 = 0.0, r2 = 0.0;  // r(k-1), r(k-2)
  for (int k = 0; k < 200; ++k) {
    const double r = first.a1 * r1 + first.a2 * r2 + first.sigma * gauss(rng);
    r2 = r1;
    r1 = r;
  }
  for (int k = 0; k < n; ++k) {
    path.At(k * step_mm, &p, &normal, &tangent);
    const Material m = material(p);
    const double r = m.a1 * r1 + m.a2 * r2 + m.sigma * gauss(rng);
    values_[k] = r;
    r2 = r1;
    r1 = r;
  }
}

double RoughnessField::At(double s) const {
  const double x = std::clamp(s / step_mm_, 0.0, static_cast<double>(values_.size() - 1));
  if (interpolation_ == RoughnessInterpolation::kNearest) {
    return values_[static_cast<std::size_t>(std::lround(x))];
  }
  const std::size_t k = std::min(static_cast<std::size_t>(x), values_.size() - 2);
  const double w = x - k;
  return (1.0 - w) * values_[k] + w * values_[k + 1];
}

}  // namespace surfmap
