// Least-squares (covariance method) AR(p) over several segments of one
// process, optionally bias-compensated for measurement noise of known
// autocovariance (ar_noise.h).
#pragma once

#include <vector>

#include <Eigen/Core>
#include "server/estimate/ar_solution.h"

namespace surfmap {

// Regresses x(t) on x(t-1..t-p) over every t with t-p inside the same segment
// (rows never span a boundary). `centered`: mean-removed segments, each longer
// than `order`. A noise autocovariance c with c(0) > 0 solves
// (X^T X - rows C) a = X^T y - rows c, C(i, j) = c(|i - j|), c = c(1..p), and
// reports innovation variance RSS/rows minus the noise's power through the
// filter (1, -a1..-ap) (white noise: noise_variance (1 + sum a_j^2)).
// Rank-deficient regressors (e.g. a pure sinusoid at order >= 3) get the
// minimum-norm solution.
ArSolution SolveLeastSquares(const std::vector<Eigen::VectorXd>& centered, int order,
                             const std::vector<double>& noise_autocovariance);

}  // namespace surfmap
