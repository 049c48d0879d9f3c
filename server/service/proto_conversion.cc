#include "server/service/proto_conversion.h"

#include <algorithm>
#include <cmath>
#include <tuple>

#include <nlohmann/json.hpp>
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "server/codec/fit_json.h"

namespace surfmap {

pb::Vec3 ToProto(const Eigen::Vector3d& v) {
  pb::Vec3 out;
  out.set_x(v.x());
  out.set_y(v.y());
  out.set_z(v.z());
  return out;
}

Eigen::Vector3d FromProto(const pb::Vec3& v) { return {v.x(), v.y(), v.z()}; }

google::protobuf::Timestamp TimestampFromUnixMs(int64_t unix_ms) {
  google::protobuf::Timestamp ts;
  ts.set_seconds(unix_ms / 1000);
  ts.set_nanos(static_cast<int32_t>((unix_ms % 1000) * 1'000'000));
  return ts;
}

void AppendSamples(const pb::TraceSamples& more, pb::TraceSamples* into) {
  into->mutable_t()->Add(more.t().begin(), more.t().end());
  into->mutable_x()->Add(more.x().begin(), more.x().end());
  into->mutable_y()->Add(more.y().begin(), more.y().end());
  into->mutable_z()->Add(more.z().begin(), more.z().end());
  into->mutable_fx()->Add(more.fx().begin(), more.fx().end());
  into->mutable_fy()->Add(more.fy().begin(), more.fy().end());
  into->mutable_fz()->Add(more.fz().begin(), more.fz().end());
  into->mutable_phases()->Add(more.phases().begin(), more.phases().end());
}

absl::StatusOr<FitOptions> FitOptionsFromProto(const pb::EstimatorSettings& settings) {
  FitOptions o;
  // Checked here, at the API, before any grid is sized from them: a client's
  // step of 2e-8 mm would ask every refit for a billion-point grid.
  if (settings.step_mm() != 0) {
    if (!(settings.step_mm() >= kMinStepMm && settings.step_mm() <= kMaxStepMm)) {
      return absl::InvalidArgumentError(absl::StrFormat(
          "estimator settings: step_mm must be in %g..%g mm (0 = default %g), got %g", kMinStepMm, kMaxStepMm,
          FitOptions{}.step_mm, settings.step_mm()));
    }
    o.step_mm = settings.step_mm();
  }
  if (settings.ar_order() != 0) {
    if (settings.ar_order() < 1 || settings.ar_order() > kMaxArOrder) {
      return absl::InvalidArgumentError(absl::StrFormat(
          "estimator settings: ar_order must be in 1..%d (0 = default %d), got %d", kMaxArOrder,
          FitOptions{}.ar_order, settings.ar_order()));
    }
    o.ar_order = settings.ar_order();
  }
  switch (settings.ar_method()) {
    case pb::AR_METHOD_BURG: o.ar_method = ArMethod::kBurg; break;
    case pb::AR_METHOD_LEAST_SQUARES: o.ar_method = ArMethod::kLeastSquares; break;
    case pb::AR_METHOD_UNSPECIFIED:
      return absl::InvalidArgumentError("estimator settings: ar_method must be BURG or LEAST_SQUARES");
    default: return absl::InvalidArgumentError("estimator settings: unknown ar_method");
  }
  // Not set: keep FitOptions' default (noise-aware), not proto3's false.
  if (settings.has_noise_aware()) o.noise_aware = settings.noise_aware();
  std::string why;
  if (!o.IsValid(&why)) return absl::InvalidArgumentError("estimator settings: " + why);
  return o;
}

absl::StatusOr<JobParams> JobParamsFromProto(const pb::JobSpec& spec, int64_t default_lease_ms) {
  JobParams p;
  p.object_id = spec.object_id();
  if (p.object_id <= 0) return absl::InvalidArgumentError("spec.object_id must be a positive object id");
  switch (spec.property()) {
    case pb::PROPERTY_FRICTION: p.property = TextureProperty::kFriction; break;
    case pb::PROPERTY_ROUGHNESS: p.property = TextureProperty::kRoughness; break;
    case pb::PROPERTY_BOTH: p.property = TextureProperty::kBoth; break;
    case pb::PROPERTY_UNSPECIFIED:
      return absl::InvalidArgumentError("spec.property must be FRICTION, ROUGHNESS or BOTH (UNSPECIFIED is rejected)");
    default: return absl::InvalidArgumentError(absl::StrCat("spec.property: unknown value ", spec.property()));
  }
  switch (spec.mode()) {
    case pb::SAMPLING_MODE_ADAPTIVE: p.mode = PlanMode::kAdaptive; break;
    case pb::SAMPLING_MODE_UNIFORM: p.mode = PlanMode::kUniform; break;
    case pb::SAMPLING_MODE_UNCERTAINTY: p.mode = PlanMode::kUncertainty; break;
    case pb::SAMPLING_MODE_UNSPECIFIED:  // the default job
    case pb::SAMPLING_MODE_BOUNDARY: p.mode = PlanMode::kBoundary; break;
    default: return absl::InvalidArgumentError(absl::StrCat("spec.mode: unknown value ", spec.mode()));
  }
  if (spec.threshold() != 0 && p.mode != PlanMode::kAdaptive) {
    return absl::InvalidArgumentError(absl::StrCat("spec.threshold is read only by ADAPTIVE; this job's mode is ",
                                                   std::string(PlanModeName(p.mode)), " (leave threshold at 0)"));
  }
  if (p.mode == PlanMode::kUncertainty && spec.budget() <= 0) {
    return absl::InvalidArgumentError("spec.budget must be > 0 for UNCERTAINTY (it stops only at the budget)");
  }
  p.coarsest_level = spec.coarsest_level();
  p.finest_level = spec.has_finest_level() ? spec.finest_level() : kAutoLevel;
  p.map_level = spec.has_map_level() ? spec.map_level() : kAutoLevel;
  for (auto [name, has, value] : {std::tuple{"finest_level", spec.has_finest_level(), spec.finest_level()},
                                  std::tuple{"map_level", spec.has_map_level(), spec.map_level()}}) {
    if (has && (value < 0 || value > 6)) {
      return absl::InvalidArgumentError(absl::StrCat("spec.", name, " must be in 0..6 (unset: chosen from the mesh), got ", value));
    }
  }
  if (spec.has_finest_level() && spec.has_map_level() && spec.map_level() < spec.finest_level()) {
    return absl::InvalidArgumentError(absl::StrCat("spec.map_level ", spec.map_level(),
                                                   " must be at least finest_level ", spec.finest_level()));
  }
  if (spec.has_finest_level() && spec.coarsest_level() > spec.finest_level()) {
    return absl::InvalidArgumentError(absl::StrCat("spec.coarsest_level ", spec.coarsest_level(),
                                                   " must be at most finest_level ", spec.finest_level()));
  }
  p.threshold = spec.threshold() != 0 ? spec.threshold() : p.threshold;
  p.budget = spec.budget();
  if (spec.has_probe()) {
    if (spec.probe().segment_length_mm() != 0) p.probe.segment_length_mm = spec.probe().segment_length_mm();
    if (spec.probe().speed_mm_s() != 0) p.probe.speed_mm_per_s = spec.probe().speed_mm_s();
    if (spec.probe().normal_force_n() != 0) p.probe.normal_force_n = spec.probe().normal_force_n();
  }
  if (!std::isfinite(spec.site_spacing_mm()) || spec.site_spacing_mm() < 0) {
    return absl::InvalidArgumentError(absl::StrCat("spec.site_spacing_mm must be >= 0 (0 = the mode's default: BOUNDARY ",
                                                   kBoundarySiteSpacingShare, " x the drag length, others the drag length)"));
  }
  p.site_spacing_mm = spec.site_spacing_mm() > 0 ? spec.site_spacing_mm()
                                                 : DefaultSiteSpacingMm(p.mode, p.probe.segment_length_mm);
  p.seed = spec.seed() != 0 ? spec.seed() : 1;
  p.max_retries = spec.max_retries() != 0 ? spec.max_retries() : p.max_retries;
  p.lease_ms = default_lease_ms;
  if (spec.has_lease()) {
    // Checked before any arithmetic: seconds * 1000 overflows int64 for a
    // client's huge value, and a Duration's nanos must be within +-1e9 with
    // the sign of its seconds.
    const google::protobuf::Duration& lease = spec.lease();
    const int64_t max_seconds = 86'400;
    if (lease.seconds() < 0 || lease.seconds() > max_seconds) {
      return absl::InvalidArgumentError(
          absl::StrCat("lease must be between 0.1 s and 24 h, got ", lease.seconds(), " s"));
    }
    if (lease.nanos() < 0 || lease.nanos() > 999'999'999) {
      return absl::InvalidArgumentError(
          absl::StrCat("lease.nanos must be in 0..999999999 for a positive duration, got ", lease.nanos()));
    }
    p.lease_ms = lease.seconds() * 1000 + lease.nanos() / 1'000'000;
  }
  if (spec.has_trace_limits()) {
    absl::StatusOr<TraceLimits> limits = TraceLimitsFromProto(spec.trace_limits());
    if (!limits.ok()) return limits.status();
    p.limits = *limits;
  }
  if (spec.has_reach()) {
    absl::StatusOr<Reachability> reach = ReachabilityFromProto(spec.reach());
    if (!reach.ok()) return reach.status();
    p.reach = *reach;
  }
  // Levels left to the server are resolved against the mesh at CreateJob;
  // everything else is checked now, with stand-ins that pass.
  JobParams check = p;
  if (check.finest_level == kAutoLevel) check.finest_level = std::max(check.coarsest_level, 0);
  if (check.map_level == kAutoLevel) check.map_level = std::max(check.finest_level, 0);
  std::string why;
  if (!check.IsValid(&why)) return absl::InvalidArgumentError("spec: " + why);
  return p;
}

absl::StatusOr<Reachability> ReachabilityFromProto(const pb::Reachability& proto) {
  Reachability r;
  if (proto.has_approach_direction()) r.approach_direction = FromProto(proto.approach_direction());
  if (proto.max_angle_deg() != 0) r.max_angle_deg = proto.max_angle_deg();
  if (proto.has_support_point()) r.support_point = FromProto(proto.support_point());
  if (proto.has_support_normal()) r.support_normal = FromProto(proto.support_normal());
  if (proto.support_clearance_mm() != 0) r.support_clearance_mm = proto.support_clearance_mm();
  std::string why;
  if (!r.IsValid(&why)) return absl::InvalidArgumentError("spec.reach: " + why);
  return r;
}

pb::Reachability ReachabilityToProto(const Reachability& r) {
  pb::Reachability proto;
  if (r.approach_direction) *proto.mutable_approach_direction() = ToProto(*r.approach_direction);
  proto.set_max_angle_deg(r.max_angle_deg);
  if (r.support_point) *proto.mutable_support_point() = ToProto(*r.support_point);
  if (r.support_normal) *proto.mutable_support_normal() = ToProto(*r.support_normal);
  proto.set_support_clearance_mm(r.support_clearance_mm);
  return proto;
}

namespace {

// Proto field, domain field: one list for both directions.
template <typename Proto, typename Visit>
void ForEachProtoLimit(Proto& proto, TraceLimits& l, Visit visit) {
  visit("max_offset_mm", proto.has_max_offset_mm(), proto.max_offset_mm(), l.max_offset_mm);
  visit("min_length_fraction", proto.has_min_length_fraction(), proto.min_length_fraction(), l.min_length_fraction);
  visit("max_length_fraction", proto.has_max_length_fraction(), proto.max_length_fraction(), l.max_length_fraction);
  visit("max_direction_deg", proto.has_max_direction_deg(), proto.max_direction_deg(), l.max_direction_deg);
  visit("max_normal_deg", proto.has_max_normal_deg(), proto.max_normal_deg(), l.max_normal_deg);
  visit("normal_force_factor", proto.has_normal_force_factor(), proto.normal_force_factor(), l.normal_force_factor);
  visit("max_mu", proto.has_max_mu(), proto.max_mu(), l.max_mu);
  visit("max_duration_factor", proto.has_max_duration_factor(), proto.max_duration_factor(), l.max_duration_factor);
}

}  // namespace

absl::StatusOr<TraceLimits> TraceLimitsFromProto(const pb::TraceLimits& proto) {
  TraceLimits limits;
  ForEachProtoLimit(proto, limits, [](const char*, bool has, double value, double& field) {
    if (has) field = value;
  });
  std::string why;
  if (!limits.IsValid(&why)) return absl::InvalidArgumentError("spec.trace_limits: " + why);
  return limits;
}

pb::TraceLimits TraceLimitsToProto(const TraceLimits& limits) {
  pb::TraceLimits proto;
  TraceLimits copy = limits;
  proto.set_max_offset_mm(copy.max_offset_mm);
  proto.set_min_length_fraction(copy.min_length_fraction);
  proto.set_max_length_fraction(copy.max_length_fraction);
  proto.set_max_direction_deg(copy.max_direction_deg);
  proto.set_max_normal_deg(copy.max_normal_deg);
  proto.set_normal_force_factor(copy.normal_force_factor);
  proto.set_max_mu(copy.max_mu);
  proto.set_max_duration_factor(copy.max_duration_factor);
  return proto;
}

pb::JobSpec JobParamsToProto(const JobParams& p) {
  pb::JobSpec spec;
  spec.set_object_id(p.object_id);
  spec.set_site_spacing_mm(p.site_spacing_mm);
  spec.set_property(p.property == TextureProperty::kFriction    ? pb::PROPERTY_FRICTION
                    : p.property == TextureProperty::kRoughness ? pb::PROPERTY_ROUGHNESS
                                                                : pb::PROPERTY_BOTH);
  spec.set_mode(p.mode == PlanMode::kAdaptive      ? pb::SAMPLING_MODE_ADAPTIVE
                : p.mode == PlanMode::kUniform     ? pb::SAMPLING_MODE_UNIFORM
                : p.mode == PlanMode::kUncertainty ? pb::SAMPLING_MODE_UNCERTAINTY
                                                   : pb::SAMPLING_MODE_BOUNDARY);
  spec.set_coarsest_level(p.coarsest_level);
  spec.set_finest_level(p.finest_level);
  spec.set_map_level(p.map_level);
  *spec.mutable_reach() = ReachabilityToProto(p.reach);
  spec.set_threshold(p.threshold);
  spec.set_budget(p.budget);
  spec.mutable_probe()->set_segment_length_mm(p.probe.segment_length_mm);
  spec.mutable_probe()->set_speed_mm_s(p.probe.speed_mm_per_s);
  spec.mutable_probe()->set_normal_force_n(p.probe.normal_force_n);
  spec.set_seed(p.seed);
  spec.set_max_retries(p.max_retries);
  spec.mutable_lease()->set_seconds(p.lease_ms / 1000);
  spec.mutable_lease()->set_nanos(static_cast<int32_t>((p.lease_ms % 1000) * 1'000'000));
  *spec.mutable_trace_limits() = TraceLimitsToProto(p.limits);
  return spec;
}

namespace {

void FillRoughness(const ArFit& r, pb::RoughnessEstimate* re) {
  for (double a : r.a) re->add_ar_coefficients(a);
  for (double e : r.a_stderr) re->add_ar_stderr(e);
  for (double k : r.reflection) re->add_reflection(k);
  re->set_sigma(r.sigma);
  re->set_stationary(r.stationary);
  re->set_acf_decay_mm(r.acf_decay_mm);
  re->set_dominant_wavelength_mm(r.dominant_wavelength_mm.value_or(0.0));
  re->set_below_noise_floor(r.below_noise_floor);
}

pb::DragPiece DragPieceToProto(const DragPiece& piece) {
  pb::DragPiece out;
  out.set_start_mm(piece.start_mm);
  out.set_end_mm(piece.end_mm);
  out.set_starts_at_change(piece.starts_at_change);
  out.set_ends_at_change(piece.ends_at_change);
  out.set_mu(piece.mu);
  out.set_mu_std(piece.mu_std);
  out.set_mu_se(piece.mu_se);
  out.set_pair_count(piece.pair_count);
  switch (piece.roughness_state) {
    case PieceRoughness::kFitted:
      out.set_roughness_state(pb::DragPiece::ROUGHNESS_STATE_FITTED);
      FillRoughness(piece.roughness, out.mutable_roughness());
      break;
    case PieceRoughness::kTooShort: out.set_roughness_state(pb::DragPiece::ROUGHNESS_STATE_TOO_SHORT); break;
    case PieceRoughness::kFitFailed: out.set_roughness_state(pb::DragPiece::ROUGHNESS_STATE_FIT_FAILED); break;
  }
  out.set_roughness_note(piece.roughness_note);
  return out;
}

}  // namespace

absl::StatusOr<pb::Fit> FitToProto(const FitRecord& record, const TraceFit* decoded) {
  TraceFit parsed;
  if (decoded == nullptr) {
    nlohmann::json j = nlohmann::json::parse(record.result_json, nullptr, false);
    absl::StatusOr<TraceFit> from_json =
        j.is_discarded() ? absl::DataLossError("not JSON") : TraceFitFromJson(j);
    if (!from_json.ok()) {
      return absl::DataLossError(absl::StrCat("stored fit ", record.id, " of trace ", record.trace_id,
                                              " cannot be read: ", from_json.status().message()));
    }
    parsed = std::move(*from_json);
    decoded = &parsed;
  }
  const TraceFit* fit = decoded;
  pb::Fit out;
  out.set_fit_id(record.id);
  out.set_version(record.version);
  out.set_estimator(record.estimator_name);
  out.set_estimator_version(record.estimator_version);
  out.set_options_json(record.options_json);
  const FrictionFit& f = fit->friction;
  pb::FrictionEstimate* fe = out.mutable_friction();
  fe->set_mu(f.mu);
  fe->set_mu_std(f.mu_std);
  fe->set_mu_median(f.mu_median);
  *fe->mutable_normal() = ToProto(f.normal);
  fe->set_pair_count(f.n_pairs);
  fe->set_window_start_mm(f.window_start_mm);
  fe->set_window_end_mm(f.window_end_mm);
  FillRoughness(fit->roughness, out.mutable_roughness());
  out.set_noise_std(fit->noise_std);
  for (const ChangePoint& change : fit->changes) out.add_change_s_mm(change.s_mm);
  for (const DragPiece& piece : fit->pieces) *out.add_pieces() = DragPieceToProto(piece);
  return out;
}

void AddFitSeries(const TraceFit& fit, double grid_step_mm, pb::Fit* out) {
  pb::FrictionEstimate* fe = out->mutable_friction();
  fe->mutable_pair_s_mm()->Assign(fit.friction.pair_s_mm.begin(), fit.friction.pair_s_mm.end());
  fe->mutable_pair_mu()->Assign(fit.friction.pair_mu.begin(), fit.friction.pair_mu.end());
  pb::RoughnessEstimate* re = out->mutable_roughness();
  re->mutable_acf()->Assign(fit.roughness.acf.begin(), fit.roughness.acf.end());
  re->set_grid_step_mm(grid_step_mm);
}

pb::JobState JobStateToProto(JobState state) {
  switch (state) {
    case JobState::kRunning: return pb::JOB_STATE_RUNNING;
    case JobState::kPaused: return pb::JOB_STATE_PAUSED;
    case JobState::kCompleted: return pb::JOB_STATE_COMPLETED;
    case JobState::kCancelled: return pb::JOB_STATE_CANCELLED;
  }
  return pb::JOB_STATE_UNSPECIFIED;
}

}  // namespace surfmap
