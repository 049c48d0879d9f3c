// Least-squares (covariance method) AR(p) over several segments of one
// process, optionally bias-compensated for white measurement noise.
#pragma once

#include <vector>

#include <Eigen/Core>
#include "server/estimate/ar_solution.h"

namespace surfmap {

// Regresses x(t) on x(t-1..t-p) over every t with t-p inside the same segment
// (rows never span a boundary). `centered`: mean-removed segments, each longer
// than `order`. noise_variance > 0 solves (X^T X - rows noise_variance I) a = X^T y
// and reports innovation variance RSS/rows - noise_variance (1 + sum a_j^2).
// Rank-deficient regressors (e.g. a pure sinusoid at order >= 3) get the
// minimum-norm solution.
ArSolution SolveLeastSquares(const std::vector<Eigen::VectorXd>& centered, int order,
                             double noise_variance);

}  // namespace surfmap
