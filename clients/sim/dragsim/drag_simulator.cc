#include "clients/sim/dragsim/drag_simulator.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "clients/sim/dragsim/roughness_field.h"

namespace surfmap {
namespace {

constexpr double kTwoPi = 2.0 * std::numbers::pi;

// Nominal motion of one pass: half-cosine speed ramps (no jerk at contact),
// cruise at speed v, total length L; time-warped by a slow speed jitter.
class PassMotion {
 public:
  PassMotion(double length, double speed, double ramp, double jitter, std::mt19937_64& rng)
      : length_(length), speed_(speed), ramp_(std::min(ramp, length / speed)) {
    duration_ = length_ / speed_ + ramp_;
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    for (int k = 0; k < 3; ++k) {
      omega_[k] = kTwoPi * (0.5 + 2.0 * unit(rng));
      amplitude_[k] = jitter * (0.5 + 0.5 * unit(rng));
      phase_[k] = kTwoPi * unit(rng);
    }
    offset_ = Delta(0.0);
  }
  double duration() const { return duration_; }
  // Warped time tau(t) = t + delta(t) - delta(0); |delta'| < 1 keeps it monotone.
  double Tau(double t) const { return t + Delta(t) - offset_; }
  double TauRate(double t) const {
    double rate = 1.0;
    for (int k = 0; k < 3; ++k) rate += amplitude_[k] * std::cos(omega_[k] * t + phase_[k]);
    return rate;
  }
  double S(double tau) const {
    tau = std::clamp(tau, 0.0, duration_);
    if (tau > duration_ - ramp_ && tau > 0.5 * duration_) return length_ - S(duration_ - tau);
    if (tau < ramp_) {
      return speed_ * (0.5 * tau - ramp_ / kTwoPi * std::sin(std::numbers::pi * tau / ramp_));
    }
    return 0.5 * speed_ * ramp_ + speed_ * (tau - ramp_);
  }
  double V(double tau) const {
    tau = std::clamp(tau, 0.0, duration_);
    if (tau > duration_ - ramp_ && tau > 0.5 * duration_) return V(duration_ - tau);
    if (tau < ramp_) return 0.5 * speed_ * (1.0 - std::cos(std::numbers::pi * tau / ramp_));
    return speed_;
  }

 private:
  double Delta(double t) const {
    double d = 0.0;
    for (int k = 0; k < 3; ++k) d += amplitude_[k] / omega_[k] * std::sin(omega_[k] * t + phase_[k]);
    return d;
  }
  double length_, speed_, ramp_, duration_;
  double omega_[3], amplitude_[3], phase_[3];
  double offset_ = 0.0;
};

}  // namespace

DragSimOptions DragSimOptions::Ideal() {
  DragSimOptions o;
  o.speed_jitter = 0.0;
  o.contact_overshoot = 0.0;
  o.force_tracking_error = 0.0;
  o.vibration_n = 0.0;
  o.stick_slip = 0.0;
  o.pause_residual = 0.0;
  o.force_noise_n = 0.0;
  o.position_noise_mm = 0.0;
  return o;
}

DragSimOptions DragSimOptions::WithDisturbancesScaled(double factor) const {
  DragSimOptions o = *this;
  for (double* amplitude : {&o.speed_jitter, &o.contact_overshoot, &o.force_tracking_error, &o.vibration_n,
                            &o.stick_slip, &o.pause_residual, &o.force_noise_n, &o.position_noise_mm}) {
    *amplitude *= factor;
  }
  return o;
}

bool DragSimOptions::IsValid(std::string* why) const {
  auto fail = [&](const char* message) {
    if (why) *why = message;
    return false;
  };
  if (!(length_mm > 0.0)) return fail("length_mm must be > 0");
  if (!(speed_mm_s > 0.0)) return fail("speed_mm_s must be > 0");
  if (!(sample_rate_hz > 0.0)) return fail("sample_rate_hz must be > 0");
  if (!(normal_force_n > 0.0)) return fail("normal_force_n must be > 0");
  if (!(pause_s >= 0.0)) return fail("pause_s must be >= 0");
  if (!(ramp_s >= 0.0)) return fail("ramp_s must be >= 0");
  if (!(roughness_step_mm > 0.0)) return fail("roughness_step_mm must be > 0");
  if (!(speed_jitter >= 0.0 && speed_jitter < 0.3)) return fail("speed_jitter must be in [0, 0.3)");
  if (!(contact_overshoot >= 0.0 && contact_overshoot < 1.0)) {
    return fail("contact_overshoot must be in [0, 1)");
  }
  if (!(contact_decay_s > 0.0)) return fail("contact_decay_s must be > 0");
  if (!(force_tracking_error >= 0.0 && force_tracking_error < 0.5)) {
    return fail("force_tracking_error must be in [0, 0.5)");
  }
  if (!(vibration_n >= 0.0 && stick_slip >= 0.0 && pause_residual >= 0.0 &&
        force_noise_n >= 0.0 && position_noise_mm >= 0.0)) {
    return fail("disturbance amplitudes must be >= 0");
  }
  return true;
}

absl::StatusOr<DragSimResult> SimulateDrag(const DragGeometry& geometry,
                                           const MaterialField& material,
                                           const DragSimOptions& o) {
  std::string why;
  if (!o.IsValid(&why)) return absl::InvalidArgumentError(absl::StrCat("DragSimOptions: ", why));
  if (absl::Status status = ValidateDragGeometry(geometry); !status.ok()) return status;
  if (!material) return absl::InvalidArgumentError("material field is empty");
  const GeometryPath path(geometry);
  // A polyline of a curve is a little shorter than the curve: allow 0.1%.
  if (path.length_mm() < o.length_mm * (1.0 - 1e-3)) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "drag geometry is %.3f mm long; the drag needs %.3f mm", path.length_mm(), o.length_mm));
  }
  const double L = std::min(o.length_mm, path.length_mm());
  const double v = o.speed_mm_s;
  const double dt = 1.0 / o.sample_rate_hz;

  // Separate streams so that, e.g., switching the noise off keeps the texture.
  std::mt19937_64 motion_rng(o.seed);
  std::mt19937_64 noise_rng(o.seed * 0x9E3779B97F4A7C15ull + 0x632BE59BD9B4E019ull);
  const RoughnessField roughness(path, material, o.roughness_step_mm,
                                 o.seed * 0xD1B54A32D192ED03ull + 0x8CB92BA72F3D8DD7ull,
                                 o.roughness_interpolation);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::normal_distribution<double> gauss(0.0, 1.0);

  const PassMotion forward_motion(L, v, o.ramp_s, o.speed_jitter, motion_rng);
  const PassMotion reverse_motion(L, v, o.ramp_s, o.speed_jitter, motion_rng);
  const double track_f1 = 0.4 + 0.4 * unit(motion_rng), track_f2 = 1.0 + unit(motion_rng);
  const double track_p1 = kTwoPi * unit(motion_rng), track_p2 = kTwoPi * unit(motion_rng);
  const double vib_phase = kTwoPi * unit(motion_rng);
  const double slip_phase = unit(motion_rng);

  const double F0 = o.normal_force_n;
  auto tracking = [&](double t) {
    return o.force_tracking_error * 0.7 *
           (std::sin(kTwoPi * track_f1 * t + track_p1) + std::sin(kTwoPi * track_f2 * t + track_p2));
  };

  DragSimResult result;
  auto& samples = result.trace.samples;
  DragTruth& truth = result.truth;
  const std::size_t estimate = static_cast<std::size_t>(
      (2.0 * forward_motion.duration() + o.pause_s) * o.sample_rate_hz + 8);
  samples.reserve(estimate);
  for (auto* vec : {&truth.s_mm, &truth.normal_force_n, &truth.friction_n, &truth.roughness_n,
                    &truth.material_mu, &truth.friction_coefficient}) {
    vec->reserve(estimate);
  }
  truth.normal.reserve(estimate);

  auto emit = [&](double t, DragPhase phase, double s_geo, const Eigen::Vector3d& point,
                  const Eigen::Vector3d& normal, const Eigen::Vector3d& against_motion, double fn,
                  double friction, double r, double mu) {
    DragSample& sample = samples.emplace_back();
    sample.t = t;
    sample.phase = phase;
    sample.position = point;
    sample.force = fn * normal + friction * against_motion;
    for (int i = 0; i < 3; ++i) {
      sample.position[i] += o.position_noise_mm * gauss(noise_rng);
      sample.force[i] += o.force_noise_n * gauss(noise_rng);
    }
    truth.s_mm.push_back(s_geo);
    truth.normal.push_back(normal);
    truth.normal_force_n.push_back(fn);
    truth.friction_n.push_back(friction);
    truth.roughness_n.push_back(r);
    truth.material_mu.push_back(mu);
    truth.friction_coefficient.push_back(friction / fn);
  };

  Eigen::Vector3d point, normal, tangent;
  double t_global = 0.0;
  auto run_pass = [&](const PassMotion& motion, bool reverse, double overshoot) {
    const double t0 = t_global;
    for (int k = 0;; ++k) {
      const double t = k * dt;
      double tau = motion.Tau(t);
      const bool last = tau >= motion.duration();
      tau = std::min(tau, motion.duration());
      const double s = motion.S(tau);
      const double speed = last ? 0.0 : motion.V(tau) * motion.TauRate(t);
      const double s_geo = reverse ? L - s : s;
      path.At(s_geo, &point, &normal, &tangent);
      const Eigen::Vector3d u = reverse ? Eigen::Vector3d(-tangent) : tangent;
      const double tg = t0 + t;
      double fn = F0 * (1.0 + overshoot * std::exp(-t / o.contact_decay_s) *
                                  std::cos(kTwoPi * o.contact_ring_hz * t)) *
                  (1.0 + tracking(tg));
      fn += o.vibration_n * (speed / v) * std::sin(kTwoPi * o.vibration_hz * tg + vib_phase);
      const Material m = material(point);
      // Stick-slip: a sawtooth (slow build-up while stuck, sudden slip) that
      // fades out above 40% of the commanded speed.
      const double slow = std::clamp(1.0 - speed / (0.4 * v), 0.0, 1.0);
      const double phase = o.stick_slip_hz * tg + slip_phase;
      const double saw = 2.0 * (phase - std::floor(phase)) - 1.0;
      const double mu_eff = m.mu * (1.0 + o.stick_slip * slow * saw);
      const double r = roughness.At(s_geo);
      emit(tg, reverse ? DragPhase::kReverse : DragPhase::kForward, s_geo, point, normal, -u, fn,
           mu_eff * fn + r, r, m.mu);
      if (last) break;
    }
    t_global = samples.back().t + dt;
  };

  run_pass(forward_motion, false, o.contact_overshoot);

  // Pause: the probe holds still at the end of the forward pass; the friction
  // it was feeling relaxes partly (residual tangential force).
  path.At(L, &point, &normal, &tangent);
  const Material end_material = material(point);
  const int pause_samples = static_cast<int>(std::lround(o.pause_s * o.sample_rate_hz));
  for (int k = 0; k < pause_samples; ++k) {
    const double tg = t_global + k * dt;
    const double fn = F0 * (1.0 + tracking(tg));
    const double relax = 1.0 - 0.3 * (k * dt) / std::max(o.pause_s, dt);
    emit(tg, DragPhase::kPause, L, point, normal, -tangent, fn,
         o.pause_residual * end_material.mu * F0 * relax, 0.0, end_material.mu);
  }
  if (pause_samples > 0) t_global = samples.back().t + dt;

  run_pass(reverse_motion, true, o.contact_overshoot / 3.0);
  result.roughness_grid = roughness.values();
  return result;
}

}  // namespace surfmap
