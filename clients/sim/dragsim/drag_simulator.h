// A seeded physical simulator of one drag measurement (docs/method.md section
// 1): forward drag, pause, reverse drag over the same path, sampled at a fixed
// rate, with the disturbances a real rig shows. Every disturbance is on by
// default and each has an option (amplitude 0) that switches it off;
// DragSimOptions::Ideal() switches them all off.
//
// Force model (by the surface on the probe), u the unit direction of motion:
//   F = Fn n - (mu_eff Fn + r(s)) u + sensor noise
// Fn: commanded normal force under force control (overshoot transient at
// contact and a smaller one at the reversal, slow tracking error, structural
// vibration scaling with speed); mu_eff: the material's mu with a stick-slip
// sawtooth while the speed is below 40% of the commanded speed (ramps);
// r(s): the roughness field at the probe's arc length (same realisation in
// both passes). During the pause the probe is still and holds a residual
// tangential force that relaxes slowly.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>
#include "absl/status/statusor.h"
#include "clients/sim/dragsim/drag_geometry.h"
#include "clients/sim/dragsim/material.h"
#include "clients/sim/dragsim/roughness_field.h"
#include "server/estimate/drag_trace.h"

namespace surfmap {

struct DragSimOptions {
  std::uint64_t seed = 1;
  double length_mm = 20.0;          // drag length from the start of the geometry
  double speed_mm_s = 10.0;         // commanded cruise speed
  double sample_rate_hz = 100.0;
  double normal_force_n = 5.0;      // commanded
  double pause_s = 0.5;
  double ramp_s = 0.3;              // half-cosine acceleration / deceleration time
  double roughness_step_mm = 0.1;   // grid of the roughness field
  RoughnessInterpolation roughness_interpolation = RoughnessInterpolation::kNearest;

  // Disturbances (0 = off).
  double speed_jitter = 0.03;            // relative speed variation (three slow sines)
  double contact_overshoot = 0.3;        // relative Fn overshoot at contact (reversal: a third)
  double contact_decay_s = 0.08;         // its exponential decay time
  double contact_ring_hz = 4.0;          // its oscillation frequency
  double force_tracking_error = 0.02;    // relative slow Fn variation
  double vibration_n = 0.03;             // structural vibration amplitude at cruise speed, N
  double vibration_hz = 17.0;
  double stick_slip = 0.3;               // relative friction sawtooth amplitude at rest
  double stick_slip_hz = 8.0;
  double pause_residual = 0.5;           // tangential force held in the pause / friction
  double force_noise_n = 0.015;          // Gaussian sensor noise per axis, N
  double position_noise_mm = 0.005;      // Gaussian position noise per axis, mm

  // All disturbances off: exact Coulomb + roughness physics.
  static DragSimOptions Ideal();
  // Every disturbance amplitude above times `factor` (0 = Ideal()'s
  // disturbances; 2 = a rig twice as noisy, shaky and sticky), to measure
  // the estimator and the map on rigs unlike this one. IsValid says when a
  // factor takes an amplitude out of its range.
  DragSimOptions WithDisturbancesScaled(double factor) const;
  bool IsValid(std::string* why) const;
};

// Ground truth, one entry per trace sample.
struct DragTruth {
  std::vector<double> s_mm;               // arc length along the geometry
  std::vector<Eigen::Vector3d> normal;    // true surface normal at the probe
  std::vector<double> normal_force_n;     // Fn
  std::vector<double> friction_n;         // mu_eff Fn + r (tangential, against the motion)
  std::vector<double> roughness_n;        // r(s)
  std::vector<double> material_mu;        // mu of the material at the probe
  // (friction_n / normal_force_n): the friction coefficient the surface
  // actually showed at the sample, texture included.
  std::vector<double> friction_coefficient;
};

struct DragSimResult {
  DragTrace trace;
  DragTruth truth;
  std::vector<double> roughness_grid;  // the realised roughness field, N, on roughness_step_mm
};

// INVALID_ARGUMENT for invalid options, an invalid geometry
// (ValidateDragGeometry) or a geometry shorter than length_mm (by more than
// 0.1%, which covers a polyline's chord error on a curve; the drag then ends
// at the end of the geometry).
absl::StatusOr<DragSimResult> SimulateDrag(const DragGeometry& geometry,
                                           const MaterialField& material,
                                           const DragSimOptions& options);

}  // namespace surfmap
