#include "server/plan/boundary_selection.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <tuple>

#include <Eigen/Geometry>
#include "server/geometry/segment_distance.h"
#include "server/plan/drag_direction.h"

namespace surfmap {
namespace {

// The data window is the middle 80 % of a drag (FitOptions' 10 % trim at
// each end).
constexpr double kWindowShare = 0.8;
// Beyond a quarter of the drag length on either side of its path, the map is
// interpolated from other drags.
constexpr double kCorridorShare = 0.25;
// Directions tried: 15 degree steps over a half turn.
constexpr int kDirections = 12;
// Candidates whose directions are searched: the best by the disc sum. The
// direction changes a candidate's gain by at most the corridor's share of its
// disc, so the best drag is among the best few discs; 16 costs ~16 x 12
// corridor sums per choice.
constexpr int kShortlist = 16;

// The kDirections steps at a vertex of normal `normal`, from
// TangentDragDirection: steps 0, 4 and 8 are VariedDragDirection's three.
std::array<Eigen::Vector3d, kDirections> ScanDirections(const Eigen::Vector3d& normal) {
  const Eigen::Vector3d n = normal.normalized();
  const Eigen::Vector3d t1 = TangentDragDirection(n);
  const Eigen::Vector3d t2 = n.cross(t1);
  std::array<Eigen::Vector3d, kDirections> directions;
  for (int k = 0; k < kDirections; ++k) {
    const double angle = std::numbers::pi * k / kDirections;
    directions[k] = std::cos(angle) * t1 + std::sin(angle) * t2;
  }
  return directions;
}

}  // namespace

double MaterialMuRiskGain(double area_mm2, double mu_se, double gap, double piece_mm, double length_mm,
                          double misclassification_cost) {
  if (!(mu_se > 0.0) || !(length_mm > 0.0) || !(piece_mm > 0.0) || !(area_mm2 > 0.0)) return 0.0;
  auto wrong = [gap](double se) { return std::erfc(gap / (2.0 * se * std::numbers::sqrt2)); };
  const double se_after = mu_se * std::sqrt(piece_mm / (piece_mm + length_mm));
  return area_mm2 * misclassification_cost * (wrong(mu_se) - wrong(se_after));
}

double SmallMaterialWeight(double smaller_area, double mean_area, double max_weight) {
  if (!(smaller_area > 0.0)) return max_weight;
  return std::clamp(mean_area / smaller_area, 1.0, max_weight);
}

BoundarySelector::BoundarySelector(const SurfaceLevel& level, double drag_length_mm,
                                   const TextureDistanceOptions& metric, double misclassification_cost,
                                   bool material_mu_risk, double small_material_weight_max,
                                   bool far_gain_expected)
    : level_(&level),
      drag_length_mm_(drag_length_mm),
      metric_(metric),
      misclassification_cost_(misclassification_cost),
      material_mu_risk_(material_mu_risk),
      small_material_weight_max_(small_material_weight_max),
      far_gain_expected_(far_gain_expected),
      half_window_mm_(0.5 * kWindowShare * drag_length_mm),
      corridor_mm_(kCorridorShare * drag_length_mm) {
  const auto& x = level.limit_positions;
  area_.assign(x.size(), 0.0);
  for (const auto& t : level.triangles) {
    const double a = 0.5 * (x[t[1]] - x[t[0]]).cross(x[t[2]] - x[t[0]]).norm() / 3.0;
    for (int v : t) area_[v] += a;
  }
  cell_mm_ = std::max(1e-6, half_window_mm_);
  lo_ = x.empty() ? Eigen::Vector3d::Zero() : x.front();
  Eigen::Vector3d hi = lo_;
  for (const auto& p : x) lo_ = lo_.cwiseMin(p), hi = hi.cwiseMax(p);
  dims_ = (((hi - lo_) / cell_mm_).array().floor().cast<int>() + 1).matrix();
  grid_.assign(static_cast<std::size_t>(dims_.x()) * dims_.y() * dims_.z(), {});
  for (int v = 0; v < static_cast<int>(x.size()); ++v) {
    const Eigen::Vector3i c = ((x[v] - lo_) / cell_mm_).array().floor().cast<int>().matrix();
    grid_[(static_cast<std::size_t>(c.z()) * dims_.y() + c.y()) * dims_.x() + c.x()].push_back(v);
  }
}

template <typename Fn>
void BoundarySelector::ForEachWithin(const Eigen::Vector3d& centre, double radius, const Fn& fn) const {
  const auto& x = level_->limit_positions;
  const Eigen::Vector3i c = ((centre - lo_) / cell_mm_).array().floor().cast<int>().matrix();
  const int span = static_cast<int>(std::ceil(radius / cell_mm_));
  const double r2 = radius * radius;
  for (int z = std::max(0, c.z() - span); z <= std::min(dims_.z() - 1, c.z() + span); ++z) {
    for (int y = std::max(0, c.y() - span); y <= std::min(dims_.y() - 1, c.y() + span); ++y) {
      for (int xi = std::max(0, c.x() - span); xi <= std::min(dims_.x() - 1, c.x() + span); ++xi) {
        for (int v : grid_[(static_cast<std::size_t>(z) * dims_.y() + y) * dims_.x() + xi]) {
          if ((x[v] - centre).squaredNorm() <= r2) fn(v);
        }
      }
    }
  }
}

int BoundarySelector::NearestVertex(const Eigen::Vector3d& p, double radius_mm) const {
  int best = -1;
  double best_d2 = 0.0;
  ForEachWithin(p, radius_mm, [&](int v) {
    const double d2 = (level_->limit_positions[v] - p).squaredNorm();
    if (best < 0 || d2 < best_d2 || (d2 == best_d2 && v < best)) best = v, best_d2 = d2;
  });
  return best;
}

double BoundarySelector::MinGain(double mu_resolution) const {
  const double corridor_area = 4.0 * half_window_mm_ * corridor_mm_ + std::numbers::pi * corridor_mm_ * corridor_mm_;
  return mu_resolution * mu_resolution * corridor_area;
}

BoundarySelector::Removable BoundarySelector::RemovableVariance(const RegionMap& map,
                                                                const std::vector<Eigen::Vector3d>& covered) const {
  const int nv = static_cast<int>(level_->limit_positions.size());
  Removable r;
  r.far.assign(nv, 0.0);
  if (far_gain_expected_) {
    r.data_mm = map.data_distance_mm();
    r.map = &map;
  }
  r.boundary.assign(nv, 0.0);
  r.across.assign(nv, Eigen::Vector3d::Zero());
  // A friction metric reads the map's own variances (the same numbers, bit
  // for bit, as before metrics existed); another rescales both terms.
  const bool friction = metric_.property == TextureProperty::kFriction;
  const double far_scale = friction ? 1.0 : map.PriorTextureVariance(metric_) / map.PriorTextureVariance(Friction());
  const auto& regions = map.regions();
  double squared_total = 0.0, misclassified_total = 0.0;
  // The weight of c between materials ma and mb (SmallMaterialWeight; 1
  // unless small_material_weight_max_ > 1, when the areas are needed).
  const bool weighed = small_material_weight_max_ > 1.0;
  const std::vector<double> material_area = weighed ? MaterialAreas(map) : std::vector<double>{};
  double mean_material_area = 0.0;
  if (weighed) {
    int materials = 0;
    for (double x : material_area) mean_material_area += x, materials += x > 0.0;
    if (materials > 0) mean_material_area /= materials;
  }
  const auto weight = [&](int ma, int mb) {
    return weighed ? SmallMaterialWeight(std::min(material_area[ma], material_area[mb]), mean_material_area,
                                         small_material_weight_max_)
                   : 1.0;
  };
  for (int v = 0; v < nv; ++v) {
    const double p = map.boundary_probability()[v];
    const int a = map.region()[v], b = map.second_region()[v];
    r.far[v] = area_[v] * map.far_variance()[v] * far_scale;
    r.boundary[v] = friction ? area_[v] * map.boundary_variance()[v]
                             : area_[v] * p * (1.0 - p) * map.ConfusionCost(a, b, metric_);
    squared_total += r.boundary[v];
    if (misclassification_cost_ > 0.0 && a >= 0 && b >= 0 && regions[a].material != regions[b].material) {
      const double misclassified =
          weight(regions[a].material, regions[b].material) * area_[v] * p * (1.0 - p) * misclassification_cost_;
      r.boundary[v] += misclassified;
      misclassified_total += misclassified;
    }
    if (r.boundary[v] > 0.0) r.across[v] = map.CrossingDirection(v);
  }
  // The far-from-data term grows with the boundaries' total, so the share of
  // drags that explore stays what it was and the cost only re-shares the
  // boundaries' drags among them.
  if (squared_total > 0.0 && misclassified_total > 0.0) {
    const double far_growth = (squared_total + misclassified_total) / squared_total;
    for (double& f : r.far) f *= far_growth;
  }
  AddMaterialRisks(map, &r);
  for (const Eigen::Vector3d& p : covered) {
    ForEachWithin(p, reach_mm(), [&](int v) {
      r.far[v] = r.boundary[v] = r.material_density[v] = 0.0;
      if (!r.data_mm.empty()) r.data_mm[v] = 0.0;
      if (!r.material.empty()) r.material[v] = -1;
    });
  }
  return r;
}

std::vector<double> BoundarySelector::MaterialAreas(const RegionMap& map) const {
  const auto& regions = map.regions();
  int materials = 0;
  for (const TextureRegion& region : regions) materials = std::max(materials, region.material + 1);
  std::vector<double> area(materials, 0.0);
  for (int v = 0; v < static_cast<int>(level_->limit_positions.size()); ++v) {
    const int region = map.region()[v];
    if (region >= 0 && regions[region].material >= 0) area[regions[region].material] += area_[v];
  }
  return area;
}

void BoundarySelector::AddMaterialRisks(const RegionMap& map, Removable* r) const {
  const int nv = static_cast<int>(level_->limit_positions.size());
  r->material_density.assign(nv, 0.0);
  if (!material_mu_risk_ || misclassification_cost_ <= 0.0) return;
  const auto& regions = map.regions();
  int materials = 0;
  for (const TextureRegion& region : regions) materials = std::max(materials, region.material + 1);
  if (materials < 2) return;
  std::vector<MaterialRisk>& m = r->materials;
  m.assign(materials, {});
  std::vector<double> mu(materials, 0.0);
  std::vector<bool> seen(materials, false);
  for (const TextureRegion& region : regions) {
    if (region.material < 0 || seen[region.material]) continue;
    seen[region.material] = true;
    MaterialRisk& risk = m[region.material];
    mu[region.material] = region.statistics.mu;
    risk.mu_se = region.statistics.mu_se;
    for (int i : region.mu_pieces) {
      const LinePiece& piece = map.pieces()[i].piece;
      risk.piece_mm += piece.end_mm - piece.start_mm;
    }
  }
  for (int a = 0; a < materials; ++a) {
    m[a].gap = std::numeric_limits<double>::infinity();
    for (int b = 0; b < materials; ++b) {
      if (b != a && seen[b]) m[a].gap = std::min(m[a].gap, std::abs(mu[a] - mu[b]));
    }
  }
  const std::vector<double> area = MaterialAreas(map);
  for (int a = 0; a < materials; ++a) m[a].area = area[a];
  r->material.assign(nv, -1);
  for (int v = 0; v < nv; ++v) {
    const int region = map.region()[v];
    if (region >= 0) r->material[v] = regions[region].material;
  }
  // For the shortlist: a drag inside the material gains Gain(window) over
  // its disc.
  const double window = 2.0 * half_window_mm_, disc = std::numbers::pi * half_window_mm_ * half_window_mm_;
  std::vector<double> density(materials);
  for (int a = 0; a < materials; ++a) density[a] = Gain(m[a], window) / disc;
  for (int v = 0; v < nv; ++v) {
    if (r->material[v] >= 0) r->material_density[v] = area_[v] * density[r->material[v]];
  }
}

double BoundarySelector::FarShareRemoved(const Removable& removable, int w, double path_mm) {
  if (removable.data_mm.empty()) return 1.0;
  // After the drag the distance to data is min(d, path_mm).
  const double before = removable.data_mm[w];
  if (!(path_mm < before)) return 0.0;
  return 1.0 - removable.map->FarVariance(path_mm) / removable.map->FarVariance(before);
}

BoundarySelector::Gains BoundarySelector::GainAlong(int v, const Eigen::Vector3d& u, const std::vector<int>& near,
                                                   const Removable& removable) const {
  const auto& x = level_->limit_positions;
  const Eigen::Vector3d a = x[v] - half_window_mm_ * u, b = x[v] + half_window_mm_ * u;
  const double h2 = half_window_mm_ * half_window_mm_;
  // The window's share in each material: of the area within half the
  // corridor of its path.
  const double band = 0.5 * corridor_mm_;
  std::vector<double> in(removable.materials.size(), 0.0);
  double band_area = 0.0;
  Gains g;
  for (int w : near) {
    const double d = DistanceToSegment(x[w], a, b);
    if (d <= corridor_mm_) g.far += removable.far[w] * FarShareRemoved(removable, w, d);
    if ((x[w] - x[v]).squaredNorm() <= h2) g.boundary += removable.boundary[w] * std::abs(u.dot(removable.across[w]));
    if (!in.empty() && d <= band) {
      band_area += area_[w];
      if (removable.material[w] >= 0) in[removable.material[w]] += area_[w];
    }
  }
  if (band_area > 0.0) {
    for (std::size_t m = 0; m < in.size(); ++m) {
      if (in[m] > 0.0) g.material += Gain(removable.materials[m], 2.0 * half_window_mm_ * in[m] / band_area);
    }
  }
  return g;
}

std::vector<int> BoundarySelector::Near(int v) const {
  std::vector<int> near;
  ForEachWithin(level_->limit_positions[v], half_window_mm_ + corridor_mm_, [&](int u) { near.push_back(u); });
  return near;
}

BoundarySelection BoundarySelector::BestOf(int v, std::span<const Eigen::Vector3d> directions,
                                           const std::vector<int>& near, const Removable& removable) const {
  BoundarySelection best;
  for (const Eigen::Vector3d& u : directions) {
    const Gains g = GainAlong(v, u, near, removable);
    const double gain = g.total();
    if (gain > best.gain) {
      best.vertex = v;
      best.gain = gain;
      best.boundary_share = g.boundary / gain;
      best.direction = u;
    }
  }
  return best;
}

BoundarySelection BoundarySelector::Select(const RegionMap& map, std::span<const char> candidate,
                                           const std::vector<Eigen::Vector3d>& covered,
                                           std::span<const DirectedCandidate> directed) const {
  BoundarySelection best;
  if (!map.has_pieces()) return best;
  const auto& x = level_->limit_positions;
  const int nv = static_cast<int>(x.size());
  const Removable removable = RemovableVariance(map, covered);
  // Shortlist by the disc sum.
  std::vector<std::pair<double, int>> scored;
  const int candidates = std::min<int>(nv, static_cast<int>(candidate.size()));
  for (int c = 0; c < candidates; ++c) {
    if (!candidate[c]) continue;
    double sum = 0.0;
    ForEachWithin(x[c], half_window_mm_, [&](int v) {
      sum += removable.far[v] + removable.boundary[v] + removable.material_density[v];
    });
    if (sum > 0.0) scored.emplace_back(-sum, c);
  }
  const std::size_t keep = std::min<std::size_t>(kShortlist, scored.size());
  std::partial_sort(scored.begin(), scored.begin() + keep, scored.end());
  scored.resize(keep);
  std::sort(scored.begin(), scored.end(), [](const auto& a, const auto& b) { return a.second < b.second; });
  for (const auto& [negative_sum, c] : scored) {
    const BoundarySelection here = BestOf(c, ScanDirections(level_->limit_normals[c]), Near(c), removable);
    if (here.gain > best.gain) best = here;
  }
  for (int i = 0; i < static_cast<int>(directed.size()); ++i) {
    const DirectedCandidate& d = directed[i];
    if (d.vertex < 0 || d.vertex >= nv) continue;
    const Gains g = GainAlong(d.vertex, d.direction, Near(d.vertex), removable);
    const double gain = g.far + g.boundary + d.extra_gain + g.material;
    if (gain > best.gain) {
      best.vertex = d.vertex;
      best.gain = gain;
      best.boundary_share = (g.boundary + d.extra_gain) / gain;
      best.direction = d.direction;
      best.directed = i;
    }
  }
  return best;
}

BoundarySelection BoundarySelector::BestDirection(const RegionMap& map, int v,
                                                  const std::vector<Eigen::Vector3d>& covered) const {
  return BestDirectionAndAmong(map, v, {}, covered).best;
}

BoundarySelector::DirectionChoice BoundarySelector::BestDirectionAndAmong(
    const RegionMap& map, int v, std::span<const Eigen::Vector3d> among,
    const std::vector<Eigen::Vector3d>& covered) const {
  if (!map.has_pieces() || v < 0 || v >= static_cast<int>(level_->limit_positions.size())) return {};
  const Removable removable = RemovableVariance(map, covered);
  const std::vector<int> near = Near(v);
  return {BestOf(v, ScanDirections(level_->limit_normals[v]), near, removable), BestOf(v, among, near, removable)};
}

}  // namespace surfmap
