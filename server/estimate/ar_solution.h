// What an AR estimator (Burg, least squares) hands back to FitAutoregressive.
#pragma once

#include <vector>

namespace surfmap {

struct ArSolution {
  std::vector<double> a;         // a1..ap
  std::vector<double> a_stderr;  // asymptotic standard errors of a1..ap
  double innovation_variance = 0.0;
  // Set when a noise correction was asked for but the de-noised moments were
  // not positive (texture below the noise): the solution is then unusable and
  // the caller refits without correction.
  bool noise_correction_failed = false;
};

}  // namespace surfmap
