#include "server/jobs/trace_plausibility.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"

namespace surfmap {
namespace {

constexpr char kPrefix[] = "implausible trace: ";
constexpr double kPi = 3.14159265358979323846;

absl::Status Implausible(const std::string& check, const std::string& detail) {
  return absl::InvalidArgumentError(absl::StrCat(kPrefix, check, ": ", detail));
}

// Not a drag at all (a broken client, not a measurement to look at): refused
// without being kept.
absl::Status Malformed(const std::string& detail) {
  return absl::InvalidArgumentError(absl::StrCat("malformed trace: ", detail));
}

// Fewer samples than any fit can use: a malformed trace, not a measurement.
constexpr size_t kMinSamples = 20;

double AngleDeg(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  const double c = a.normalized().dot(b.normalized());
  return std::acos(std::clamp(c, -1.0, 1.0)) * 180.0 / kPi;
}

// The commanded drag's duration: both passes at the commanded speed, and the
// pause and ramps a rig adds (a few seconds at most).
double CommandedDurationS(const ProbeCommand& command) {
  return 2.0 * command.probe.segment_length_mm / command.probe.speed_mm_per_s + 3.0;
}

// How far along the path, either side of the pair nearest the commanded
// site, the estimated normals may match the commanded one: the service's
// surface and the rig's meet a sharp edge within a fraction of a mm of each
// other, and a site on the edge itself may be commanded with either face's
// normal.
constexpr double kSiteNormalReachMm = 1.0;
// A few pairs (0.1 mm apart at the paper's rig) either side: a sharp edge's
// turn, over ~1 mm of a probe's tip, stays resolved.
constexpr double kPairNormalSmoothingMm = 0.3;

// The smallest angle, degrees, between `commanded` and the per-pair normals
// estimated within kSiteNormalReachMm of where the drag passed the site.
// Over a curved surface or a CAD part's sharp edge the normal turns along
// the drag (by 90 degrees over an edge), so the drag's mean normal is not the
// site's. `forward` holds the forward samples the pairs index.
double SiteNormalAngleDeg(const std::vector<const DragSample*>& forward, const FrictionFit& f,
                          const Eigen::Vector3d& site, const Eigen::Vector3d& commanded) {
  std::size_t nearest = 0;
  double best = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < f.pair_normal.size(); ++i) {
    const double d = (forward[f.first_forward_sample + i]->position - site).squaredNorm();
    if (d < best) best = d, nearest = i;
  }
  // Each pair's normal is first averaged over kPairNormalSmoothingMm either
  // side, so that the smallest angle is not one noisy pair's (a trace whose
  // friction swamps its normal force has pair normals all over the sphere).
  // Prefix sums over the pairs, which are in path order: linear in the
  // pairs, however densely a rig samples.
  const std::vector<double>& s = f.pair_s_mm;
  std::vector<Eigen::Vector3d> prefix(f.pair_normal.size() + 1, Eigen::Vector3d::Zero());
  for (std::size_t i = 0; i < f.pair_normal.size(); ++i) prefix[i + 1] = prefix[i] + f.pair_normal[i];
  auto first_at_or_after = [&](double at) { return std::lower_bound(s.begin(), s.end(), at) - s.begin(); };
  auto first_after = [&](double at) { return std::upper_bound(s.begin(), s.end(), at) - s.begin(); };
  double angle = 180.0;
  for (auto i = first_at_or_after(s[nearest] - kSiteNormalReachMm); i < first_after(s[nearest] + kSiteNormalReachMm);
       ++i) {
    const Eigen::Vector3d sum = prefix[first_after(s[i] + kPairNormalSmoothingMm)] -
                                prefix[first_at_or_after(s[i] - kPairNormalSmoothingMm)];
    if (sum.norm() > 0.0) angle = std::min(angle, AngleDeg(sum, commanded));
  }
  return angle;
}

}  // namespace

bool TraceLimits::IsValid(std::string* why) const {
  auto fail = [&](std::string text) {
    if (why) *why = std::move(text);
    return false;
  };
  auto positive = [](double v) { return std::isfinite(v) && v > 0; };
  if (!positive(max_offset_mm) || max_offset_mm > 1000) return fail("max_offset_mm must be in (0, 1000] mm");
  if (!(min_length_fraction >= 0 && min_length_fraction < 1)) return fail("min_length_fraction must be in [0, 1)");
  if (!(max_length_fraction > 1 && max_length_fraction <= 100)) return fail("max_length_fraction must be in (1, 100]");
  if (!(max_direction_deg > 0 && max_direction_deg <= 90)) return fail("max_direction_deg must be in (0, 90]");
  if (!(max_normal_deg > 0 && max_normal_deg <= 90)) return fail("max_normal_deg must be in (0, 90]");
  if (!(normal_force_factor > 1 && normal_force_factor <= 1000)) return fail("normal_force_factor must be in (1, 1000]");
  if (!(max_mu > 0 && max_mu <= 100)) return fail("max_mu must be in (0, 100]");
  if (!(max_duration_factor >= 1 && max_duration_factor <= 1e4)) return fail("max_duration_factor must be in [1, 10000]");
  if (!positive(min_rate_hz) || !positive(max_rate_hz) || min_rate_hz >= max_rate_hz || max_rate_hz > 1e7) {
    return fail("min_rate_hz and max_rate_hz must satisfy 0 < min < max <= 1e7");
  }
  return true;
}

absl::Status CheckTraceAgainstCommand(const DragTrace& trace, const ProbeCommand& command, const TraceLimits& limits) {
  const std::vector<DragSample>& s = trace.samples;
  if (s.size() < kMinSamples) {
    return Malformed(absl::StrCat("too few samples: ", s.size(), "; a drag has at least ", kMinSamples));
  }
  const double length = command.probe.segment_length_mm;

  // finite, time, offset, forward path and its extent: one pass.
  const double reach = length + limits.max_offset_mm;
  double forward_length = 0.0;
  Eigen::Vector3d first_forward = Eigen::Vector3d::Zero(), last_forward = Eigen::Vector3d::Zero();
  bool seen_forward = false;
  for (size_t i = 0; i < s.size(); ++i) {
    const DragSample& d = s[i];
    if (!std::isfinite(d.t) || !d.position.allFinite() || !d.force.allFinite()) {
      return Malformed(absl::StrCat("sample ", i, " has a value that is not a finite number"));
    }
    if (i > 0 && !(d.t > s[i - 1].t)) {
      return Malformed(absl::StrFormat("sample %d: t = %.9g s does not follow %.9g s (time must increase)", i, d.t,
                                       s[i - 1].t));
    }
    const double offset = (d.position - command.position).norm();
    if (offset > reach) {
      return Implausible("offset", absl::StrFormat("sample %d is %.1f mm from the commanded site; the limit is %.1f mm "
                                                   "(segment %.1f mm + max_offset_mm %.1f): another object, another "
                                                   "frame, or positions in other units?",
                                                   i, offset, reach, length, limits.max_offset_mm));
    }
    if (d.phase == DragPhase::kForward) {
      if (seen_forward) forward_length += (d.position - last_forward).norm();
      if (!seen_forward) first_forward = d.position;
      last_forward = d.position;
      seen_forward = true;
    }
  }
  const double duration = s.back().t - s.front().t;
  const double max_duration = limits.max_duration_factor * CommandedDurationS(command) + 30.0;
  if (duration > max_duration) {
    return Implausible("time", absl::StrFormat("the drag lasts %.4g s; the limit is %.4g s (%.1f mm at %.4g mm/s)",
                                               duration, max_duration, length, command.probe.speed_mm_per_s));
  }
  const double rate = (static_cast<double>(s.size()) - 1.0) / duration;
  if (rate < limits.min_rate_hz || rate > limits.max_rate_hz) {
    return Implausible("rate", absl::StrFormat("%.4g samples/s; the limits are %.4g..%.4g", rate, limits.min_rate_hz,
                                               limits.max_rate_hz));
  }
  if (!seen_forward) return Implausible("length", "no forward sample");
  const double min_length = limits.min_length_fraction * length, max_length = limits.max_length_fraction * length;
  if (forward_length < min_length || forward_length > max_length) {
    return Implausible("length", absl::StrFormat("the forward path is %.3g mm; the limits are %.3g..%.3g mm "
                                                 "(segment %.1f mm)",
                                                 forward_length, min_length, max_length, length));
  }
  // Seen along the site's normal: a drag over a curved surface, or over a
  // CAD part's sharp edge, turns down with the surface (its chord dips up to
  // 45 degrees and more), not aside.
  const Eigen::Vector3d chord3 = last_forward - first_forward;
  const Eigen::Vector3d chord = chord3 - chord3.dot(command.normal) * command.normal;
  if (chord.norm() > 1e-9) {
    const double angle = AngleDeg(chord, command.drag_direction);
    const double off_line = std::min(angle, 180.0 - angle);  // either way along the commanded line
    if (off_line > limits.max_direction_deg) {
      return Implausible("direction", absl::StrFormat("the forward pass runs %.1f deg off the commanded drag line; "
                                                      "the limit is %.1f deg",
                                                      off_line, limits.max_direction_deg));
    }
  }
  return absl::OkStatus();
}

absl::Status CheckTraceNearSurface(double max_distance_mm, int sample, const TraceLimits& limits) {
  if (max_distance_mm > limits.max_offset_mm) {
    return Implausible("surface", absl::StrFormat("sample %d is %.1f mm from the object's surface; the limit is %.1f mm "
                                                  "(max_offset_mm): a drag on another object, in another frame, or "
                                                  "positions in other units?",
                                                  sample, max_distance_mm, limits.max_offset_mm));
  }
  return absl::OkStatus();
}

absl::Status CheckFitAgainstCommand(const DragTrace& trace, const TraceFit& fit, const ProbeCommand& command,
                                    const TraceLimits& limits) {
  std::vector<const DragSample*> forward;
  for (const DragSample& d : trace.samples) {
    if (d.phase == DragPhase::kForward) forward.push_back(&d);
  }
  const FrictionFit& f = fit.friction;
  // Per-pair normals as FitTrace makes them: one per forward sample of the
  // window, in path order.
  const bool per_pair = !f.pair_normal.empty() && f.pair_s_mm.size() == f.pair_normal.size() &&
                        std::is_sorted(f.pair_s_mm.begin(), f.pair_s_mm.end()) && f.first_forward_sample >= 0 &&
                        f.first_forward_sample + f.pair_normal.size() <= forward.size();
  const double normal_angle = per_pair ? SiteNormalAngleDeg(forward, f, command.position, command.normal)
                                        : AngleDeg(f.normal, command.normal);
  if (normal_angle > limits.max_normal_deg) {
    return Implausible("normal", absl::StrFormat("the estimated surface normal at the site is %.1f deg from the "
                                                 "commanded one; the limit is %.1f deg: a trace in another frame?",
                                                 normal_angle, limits.max_normal_deg));
  }
  // Mean normal force over the forward pass, each sample along the normal
  // estimated where it was (a drag's normal turns with the surface).
  double sum = 0.0;
  int n = 0;
  if (per_pair) {
    for (std::size_t i = 0; i < f.pair_normal.size(); ++i) {
      sum += forward[f.first_forward_sample + i]->force.dot(f.pair_normal[i]);
      ++n;
    }
  } else {
    for (const DragSample* d : forward) {
      sum += d->force.dot(f.normal);
      ++n;
    }
  }
  const double commanded = command.probe.normal_force_n;
  const double normal_force = n > 0 ? sum / n : 0.0;
  if (normal_force < commanded / limits.normal_force_factor || normal_force > commanded * limits.normal_force_factor) {
    return Implausible("force", absl::StrFormat("the mean normal force is %.3g N; the limits are %.3g..%.3g N "
                                                "(commanded %.3g N)",
                                                normal_force, commanded / limits.normal_force_factor,
                                                commanded * limits.normal_force_factor, commanded));
  }
  const double mu = fit.friction.mu;
  if (!(mu >= 0.0) || mu > limits.max_mu) {
    return Implausible("friction", absl::StrFormat("mu = %.4g; friction must oppose the motion with mu in 0..%.3g "
                                                   "(forces with the wrong sign, or in the wrong frame?)",
                                                   mu, limits.max_mu));
  }
  return absl::OkStatus();
}

std::string PlausibilityCheckName(const absl::Status& refusal) {
  const std::string_view message(refusal.message().data(), refusal.message().size());
  const std::string_view prefix = kPrefix;
  if (message.substr(0, prefix.size()) != prefix) return "";
  const std::string_view rest = message.substr(prefix.size());
  return std::string(rest.substr(0, rest.find(':')));
}

}  // namespace surfmap
