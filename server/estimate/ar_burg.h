// Burg's method for AR(p) over several segments of one process, optionally
// compensated for measurement noise of known autocovariance (see
// ArFitOptions::noise_autocovariance).
#pragma once

#include <vector>

#include <Eigen/Core>
#include "server/estimate/ar_solution.h"

namespace surfmap {

// `centered`: mean-removed segments, each longer than `order` (the caller
// validates). `variance`: their pooled lag-0 autocovariance (> 0).
// `noise_autocovariance`: the noise's autocovariance at lags 0, 1, ...
// (ar_noise.h); empty or a zero lag 0 = plain Burg. Standard errors are the asymptotic
// sqrt(diag(sigma^2 Gamma_p^-1) / n) of the fitted model.
ArSolution SolveBurg(const std::vector<Eigen::VectorXd>& centered, int order, double variance,
                     const std::vector<double>& noise_autocovariance);

}  // namespace surfmap
