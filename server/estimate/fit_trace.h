// FitTrace: friction and roughness from one drag trace.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>
#include "absl/status/statusor.h"
#include "server/estimate/drag_trace.h"
#include "server/estimate/roughness.h"

namespace surfmap {

struct FitOptions {
  double step_mm = 0.1;           // roughness grid step L
  int ar_order = 2;
  ArMethod ar_method = ArMethod::kBurg;
  bool noise_aware = true;        // use the pause to de-bias roughness
  // Data window: exclude this share of the travelled path at each end of the
  // common forward/reverse path (transients, stick-slip at low speed).
  double window_trim_fraction = 0.2;
  bool IsValid(std::string* why) const;
};

struct FrictionFit {
  double mu = 0.0;                // mean of the per-point mu over the window
  double mu_std = 0.0;
  double mu_median = 0.0;
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  // mean unit normal
  int n_pairs = 0;
  double window_start_mm = 0.0;   // along the forward path from its first sample
  double window_end_mm = 0.0;
  std::vector<double> pair_s_mm;  // arc length of each pair
  std::vector<double> pair_mu;    // per-point mu
};

struct TraceFit {
  FrictionFit friction;
  ArFit roughness;
  double noise_std = 0.0;         // force noise during the pause, N
  double path_length_mm = 0.0;    // forward path length
};

// Errors (INVALID_ARGUMENT, message naming the problem): no forward or reverse
// pass, too few samples, a reverse pass that does not retrace the forward path,
// zero force, non-finite values, invalid options.
absl::StatusOr<TraceFit> FitTrace(const DragTrace& trace, const FitOptions& options);

}  // namespace surfmap
