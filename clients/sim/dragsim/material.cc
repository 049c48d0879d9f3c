#include "clients/sim/dragsim/material.h"

#include <cmath>

namespace surfmap {

MaterialField UniformMaterial(const Material& material) {
  return [material](const Eigen::Vector3d&) { return material; };
}

MaterialField SplitMaterial(const Material& inside, const Material& outside,
                            const Eigen::Vector3d& point, const Eigen::Vector3d& normal) {
  return [=](const Eigen::Vector3d& p) { return (p - point).dot(normal) < 0.0 ? inside : outside; };
}

double ArProcessVariance(const Material& m) {
  // gamma0 = sigma^2 (1 - a2) / ((1 + a2) ((1 - a2)^2 - a1^2)) for AR(2).
  const double d = (1.0 + m.a2) * ((1.0 - m.a2) * (1.0 - m.a2) - m.a1 * m.a1);
  if (m.sigma == 0.0 || !(d > 0.0) || !(std::abs(m.a2) < 1.0)) return 0.0;
  return m.sigma * m.sigma * (1.0 - m.a2) / d;
}

}  // namespace surfmap
