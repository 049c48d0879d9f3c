// Coulomb friction by the differential method (Lloyd & Pai 2001, docs/method.md
// section 2): pair each forward point with the same point on the reverse pass;
// with fh, rh the unit forces and theta the angle between them,
//   mu = tan(theta / 2),   n = (fh + rh) / |fh + rh|,
// independent of speed, force magnitudes, probe orientation and the normal.
#pragma once

#include <span>
#include <string>
#include <vector>

#include <Eigen/Core>
#include "absl/status/statusor.h"
#include "server/estimate/data_window.h"
#include "server/estimate/drag_trace.h"
#include "server/estimate/path_pairing.h"

namespace surfmap {

struct FrictionOptions {
  // A contact force below this is "no contact": a free force sensor reads its
  // noise (~0.01-0.02 N per axis), far below any usable contact force (the
  // method's commanded force is 5 N) and far above it when the probe is lifted.
  double min_contact_force_n = 0.1;
  int min_pairs = 10;  // fewer forward samples in the window is an error
  bool IsValid(std::string* why) const;
};

struct FrictionFit {
  double mu = 0.0;                // mean of the per-point mu over the window
  double mu_std = 0.0;            // sample standard deviation of the per-point mu
  double mu_median = 0.0;
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  // normalised mean of per-pair normals
  int n_pairs = 0;
  double window_start_mm = 0.0;   // along the forward path from its first sample
  double window_end_mm = 0.0;
  int first_forward_sample = 0;   // pairs are forward samples first..first + n_pairs - 1
  std::vector<double> pair_s_mm;  // arc length of each pair
  std::vector<double> pair_mu;    // per-point mu
  std::vector<Eigen::Vector3d> pair_normal;  // per-point unit normal
};

// Pairs every forward sample inside `window` with the reverse force
// interpolated at the same arc length. The per-point mu is signed: negative
// when, relative to the reverse pass, the forward force leans along the motion
// (possible point-wise on rough surfaces), so the mean is not biased upward.
// INVALID_ARGUMENT for a contact force below min_contact_force_n (naming the
// sample), fewer than min_pairs pairs, opposite unit forces (no normal).
absl::StatusOr<FrictionFit> FitFriction(std::span<const DragSample> forward,
                                        std::span<const DragSample> reverse,
                                        const PathPairing& pairing, const DataWindow& window,
                                        const FrictionOptions& options = {});

}  // namespace surfmap
