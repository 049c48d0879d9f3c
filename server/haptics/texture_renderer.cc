#include "server/haptics/texture_renderer.h"

#include <cmath>
#include <limits>

#include <Eigen/Geometry>
#include "absl/strings/str_cat.h"

namespace surfmap::haptics {
namespace {

// Hash of the grid cell holding `p`, in [0, 2^40): far from int64 overflow
// when the stroke's cells are added (a 2^40-cell stroke is 10^8 km at 0.1 mm).
std::int64_t StrokeOrigin(const Eigen::Vector3d& p, double step) {
  std::uint64_t h = 0x9e3779b97f4a7c15ULL;
  for (int a = 0; a < 3; ++a) {
    const auto cell = static_cast<std::uint64_t>(static_cast<std::int64_t>(std::floor(p[a] / step)));
    h ^= cell + 0x9e3779b97f4a7c15ULL + (h << 6) + (h >> 2);
    h *= 0xff51afd7ed558ccdULL;
    h ^= h >> 33;
  }
  return static_cast<std::int64_t>(h & ((std::uint64_t{1} << 40) - 1));
}

}  // namespace

bool TextureRendererOptions::IsValid(std::string* why) const {
  auto fail = [&](std::string message) {
    if (why) *why = std::move(message);
    return false;
  };
  if (!std::isfinite(min_speed_mm_s) || min_speed_mm_s < 0) return fail("min_speed_mm_s must be finite and >= 0");
  if (!(contact_distance_mm > 0)) return fail("contact_distance_mm must be > 0");
  return true;
}

void ProbeState::Reset() {
  triangle = -1;
  touching = false;
  point.setZero();
  stroke.setZero();
  arc_length_mm = 0.0;
  stroke_origin = 0;
  impulse.order = -1;
}

TextureRenderer::TextureRenderer(TextureMap map, const TextureRendererOptions& options)
    : map_(std::move(map)), options_(options), locator_(map_.positions, map_.triangles), texture_(options.seed) {
  log_sigma_.assign(map_.positions.size(), std::numeric_limits<double>::quiet_NaN());
  if (map_.has_roughness()) {
    for (size_t v = 0; v < map_.sigma.size(); ++v) {
      if (std::isfinite(map_.sigma[v]) && map_.sigma[v] > 0) log_sigma_[v] = std::log(map_.sigma[v]);
    }
  }
}

absl::StatusOr<std::unique_ptr<TextureRenderer>> TextureRenderer::Create(TextureMap map,
                                                                         const TextureRendererOptions& options) {
  if (absl::Status s = ValidateTextureMap(map); !s.ok()) return s;
  std::string why;
  if (!options.IsValid(&why)) return absl::InvalidArgumentError(absl::StrCat("renderer options: ", why));
  if (map.ar_order > kMaxArOrder) {
    return absl::InvalidArgumentError(absl::StrCat("AR order ", map.ar_order, " above ", kMaxArOrder));
  }
  return std::unique_ptr<TextureRenderer>(new TextureRenderer(std::move(map), options));
}

SurfaceLookup TextureRenderer::Locate(const Eigen::Vector3d& position, ProbeState& state) const {
  SurfaceLookup out;
  const TriangleHit hit = locator_.Closest(position, state.triangle);
  if (hit.triangle < 0) return out;
  state.triangle = hit.triangle;
  out.triangle = hit.triangle;
  out.barycentric = hit.barycentric;
  out.position = hit.position;
  out.distance_mm = std::sqrt(hit.squared_distance);
  const auto& t = map_.triangles[hit.triangle];
  Eigen::Vector3d n;
  if (!map_.normals.empty()) {
    n = hit.barycentric[0] * map_.normals[t[0]] + hit.barycentric[1] * map_.normals[t[1]] +
        hit.barycentric[2] * map_.normals[t[2]];
  } else {
    n = (map_.positions[t[1]] - map_.positions[t[0]]).cross(map_.positions[t[2]] - map_.positions[t[0]]);
  }
  const double norm = n.norm();
  out.normal = norm > 0 ? Eigen::Vector3d(n / norm) : Eigen::Vector3d::UnitZ();
  return out;
}

ContactSample TextureRenderer::Sample(ProbeState& state, const Eigen::Vector3d& position,
                                      const Eigen::Vector3d& velocity, double normal_force_n) const {
  ContactSample out;
  out.surface = Locate(position, state);
  if (out.surface.triangle < 0 || !(out.surface.distance_mm <= options_.contact_distance_mm)) {
    state.touching = false;  // the stroke ends; the hint stays useful
    return out;
  }
  out.in_contact = true;
  const auto& t = map_.triangles[out.surface.triangle];
  const Eigen::Vector3d& w = out.surface.barycentric;
  const Eigen::Vector3d& n = out.surface.normal;

  // Arc length: the tangential step between successive surface points, signed
  // by whether it continues the stroke or goes back along it.
  if (state.touching) {
    Eigen::Vector3d d = out.surface.position - state.point;
    d -= d.dot(n) * n;
    const double len = d.norm();
    if (len > 0) {
      if (state.stroke.squaredNorm() == 0) state.stroke = d / len;
      const double sign = d.dot(state.stroke) >= 0 ? 1.0 : -1.0;
      state.arc_length_mm += sign * len;
      state.stroke = sign * d / len;  // follows the path's curvature, keeps the orientation
    }
  } else {
    state.touching = true;
    state.stroke.setZero();
    state.arc_length_mm = 0.0;
    state.stroke_origin = StrokeOrigin(out.surface.position, map_.grid_step_mm);
  }
  state.point = out.surface.position;
  out.arc_length_mm = state.arc_length_mm;

  // The vertices that count: with sharp regions, those of the heaviest
  // vertex's region (a vertex without a region joins nobody else's).
  int heaviest = 0;
  for (int c = 1; c < 3; ++c) {
    if (w[c] > w[heaviest]) heaviest = c;
  }
  if (!map_.region.empty()) out.region = map_.region[t[heaviest]];
  double weight[3] = {w[0], w[1], w[2]};
  if (options_.sharp_regions && !map_.region.empty()) {
    for (int c = 0; c < 3; ++c) {
      if (map_.region[t[c]] != out.region) weight[c] = 0.0;
    }
  }

  // Friction coefficient over the vertices that know it.
  double mu_sum = 0.0, mu_weight = 0.0;
  for (int c = 0; c < 3; ++c) {
    const double mu = map_.mu[t[c]];
    if (std::isfinite(mu) && weight[c] > 0) {
      mu_sum += weight[c] * mu;
      mu_weight += weight[c];
    }
  }
  // A point exactly on an edge gives weight 0 to the opposite vertex: when
  // only that vertex knows mu, fall back to it rather than to "unknown".
  if (mu_weight <= 0) {
    for (int c = 0; c < 3; ++c) {
      if (std::isfinite(map_.mu[t[c]])) {
        mu_sum = map_.mu[t[c]];
        mu_weight = 1.0;
        break;
      }
    }
  }
  out.mu_known = mu_weight > 0;
  out.mu = out.mu_known ? mu_sum / mu_weight : 0.0;

  // Roughness model: reflection coefficients and log sigma over the vertices
  // with a fit, amplitude scaled by their share of the weight.
  if (map_.has_roughness()) {
    double k[kMaxArOrder] = {};
    double log_sigma = 0.0, rough_weight = 0.0, total_weight = 0.0;
    for (int c = 0; c < 3; ++c) {
      total_weight += weight[c];
      if (!std::isfinite(log_sigma_[t[c]]) || weight[c] <= 0) continue;
      rough_weight += weight[c];
      log_sigma += weight[c] * log_sigma_[t[c]];
      for (int j = 0; j < map_.ar_order; ++j) k[j] += weight[c] * map_.ReflectionAt(t[c], j);
    }
    if (rough_weight > 0) {
      for (int j = 0; j < map_.ar_order; ++j) k[j] /= rough_weight;
      double a[kMaxArOrder];
      ReflectionToArInPlace(k, map_.ar_order, a);
      UpdateImpulse(a, map_.ar_order, state.impulse);
      out.sigma = rough_weight / total_weight * std::exp(log_sigma / rough_weight);
      out.cell = state.stroke_origin + static_cast<std::int64_t>(std::llround(state.arc_length_mm / map_.grid_step_mm));
      out.roughness_n = texture_.Roughness(out.cell, out.sigma, state.impulse);
    }
  }

  const Eigen::Vector3d v_t = velocity - velocity.dot(n) * n;
  const double speed = v_t.norm();
  if (speed > options_.min_speed_mm_s && std::isfinite(speed)) {
    const Eigen::Vector3d u = v_t / speed;
    const double fn = normal_force_n > 0 ? normal_force_n : 0.0;
    out.friction_force = -out.mu * fn * u;
    out.roughness_force = -out.roughness_n * u;
    out.tangential_force = out.friction_force + out.roughness_force;
  }
  return out;
}

}  // namespace surfmap::haptics
