// Surface materials for the drag simulator: Coulomb friction plus an AR(2)
// roughness (force variation over arc length, grid step 0.1 mm, in N).
#pragma once

#include <functional>

#include <Eigen/Core>

namespace surfmap {

struct Material {
  double mu = 0.0;     // Coulomb friction coefficient
  double a1 = 0.0;     // AR(2) roughness coefficients on the 0.1 mm grid
  double a2 = 0.0;
  double sigma = 0.0;  // AR(2) innovation standard deviation, N
};

// Lloyd & Pai 2001 values where the paper gives them.
inline constexpr Material kGlass{0.106, 0.5, 0.0, 0.003};  // smooth: texture below sensor noise
inline constexpr Material kRubber{0.305, 0.60, 0.25, 0.11};
inline constexpr Material kMasonite{0.25, 1.61, -0.73, 0.16};
// Fine sandpaper (paper's bottle patches, mu ~ 0.5): grit gives a strong,
// fast-decorrelating texture (real poles 0.5 and -0.2, correlation ~0.15 mm).
inline constexpr Material kSandpaper{0.5, 0.30, 0.10, 0.25};

// The material at a surface point (mm). Lets a drag cross a region boundary.
using MaterialField = std::function<Material(const Eigen::Vector3d& point)>;

MaterialField UniformMaterial(const Material& material);

// `inside` where (p - point) . normal < 0, `outside` elsewhere: a straight
// boundary through `point` (a plane in 3-D).
MaterialField SplitMaterial(const Material& inside, const Material& outside,
                            const Eigen::Vector3d& point, const Eigen::Vector3d& normal);

// Process variance of the stationary AR(2) process of `m` (0 when sigma = 0
// or the process is not stationary): the expected lag-0 autocovariance, N^2.
double ArProcessVariance(const Material& m);

}  // namespace surfmap
