#include "server/map/region_map.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <set>

#include <Eigen/Dense>
#include <Eigen/Geometry>
#include "absl/strings/str_cat.h"
#include "absl/strings/strip.h"
#include "server/estimate/texture.h"
#include "server/map/mixture_materials.h"
#include "server/map/piece_resplit.h"
#include "server/map/texture_assignment.h"

namespace surfmap {
namespace {

// The point halfway along a polyline (its only point if it has one).
Eigen::Vector3d HalfwayAlong(const std::vector<Eigen::Vector3d>& points) {
  double length = 0.0;
  for (std::size_t k = 1; k < points.size(); ++k) length += (points[k] - points[k - 1]).norm();
  double left = 0.5 * length;
  for (std::size_t k = 1; k < points.size(); ++k) {
    const double step = (points[k] - points[k - 1]).norm();
    if (step >= left && step > 0.0) return points[k - 1] + (left / step) * (points[k] - points[k - 1]);
    left -= step;
  }
  return points.back();
}

// The roughness coordinates of `metric` (reflection coefficients and log
// sigma, each over its scale), their variance summed over the pieces with
// roughness, times mu_scale^2; 0 with fewer than two such pieces.
double RoughnessVariance(const std::vector<MapPiece>& pieces, const TextureDistanceOptions& metric) {
  std::vector<Eigen::VectorXd> rows;
  for (const MapPiece& p : pieces) {
    if (!p.piece.has_roughness()) continue;
    const auto& k = p.piece.texture.reflection;
    Eigen::VectorXd row(k.size() + 1);
    for (std::size_t j = 0; j < k.size(); ++j) row[j] = k[j] / metric.reflection_scale;
    row[k.size()] = std::log(std::max(p.piece.texture.sigma, kTextureSigmaFloor)) / metric.log_sigma_scale;
    if (!rows.empty() && row.size() != rows.front().size()) continue;  // one model order: the first piece's
    rows.push_back(row);
  }
  if (rows.size() < 2) return 0.0;
  Eigen::VectorXd mean = Eigen::VectorXd::Zero(rows.front().size());
  for (const auto& r : rows) mean += r;
  mean /= static_cast<double>(rows.size());
  double var = 0.0;
  for (const auto& r : rows) var += (r - mean).squaredNorm();
  var /= static_cast<double>(rows.size() - 1);
  return metric.mu_scale * metric.mu_scale * var;
}

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kMaxReflection = 0.999;  // keep medians of reflection coefficients strictly stationary

double Median(std::vector<double> v) {
  const std::size_t n = v.size();
  std::nth_element(v.begin(), v.begin() + n / 2, v.end());
  double m = v[n / 2];
  if (n % 2 == 0) m = 0.5 * (m + *std::max_element(v.begin(), v.begin() + n / 2));
  return m;
}

// The points of a polyline with no gap longer than `spacing`.
std::vector<Eigen::Vector3d> Resample(const std::vector<Eigen::Vector3d>& points, double spacing) {
  std::vector<Eigen::Vector3d> out;
  if (points.empty()) return out;
  out.push_back(points.front());
  for (std::size_t i = 1; i < points.size(); ++i) {
    const Eigen::Vector3d step = points[i] - points[i - 1];
    const int parts = std::max(1, static_cast<int>(std::ceil(step.norm() / spacing - 1e-9)));
    for (int k = 1; k <= parts; ++k) out.push_back(points[i - 1] + (static_cast<double>(k) / parts) * step);
  }
  return out;
}

Eigen::Vector3d Tangent(const Eigen::Vector3d& v, const Eigen::Vector3d& normal) { return v - v.dot(normal) * normal; }

}  // namespace

bool RegionMapOptions::IsValid(std::string* why) const {
  auto fail = [why](std::string m) {
    if (why != nullptr) *why = std::move(m);
    return false;
  };
  std::string inner;
  if (!merge.IsValid(&inner)) return fail(absl::StrCat("merge: ", inner));
  if (!known_split.IsValid(&inner)) return fail(absl::StrCat("known_split: ", inner));
  if (!links.IsValid(&inner)) return fail(absl::StrCat("links: ", inner));
  if (min_texture_rows < 3) return fail("min_texture_rows must be >= 3");
  if (min_fitted_pieces_for_mu < 0) return fail("min_fitted_pieces_for_mu must be >= 0 (0 = every piece)");
  if (!(std::isfinite(min_mu_piece_mm) && min_mu_piece_mm >= 0.0)) return fail("min_mu_piece_mm must be >= 0");
  if (!(std::isfinite(point_spacing_mm) && point_spacing_mm > 0.0)) return fail("point_spacing_mm must be > 0");
  if (!(std::isfinite(correlation_length_mm) && correlation_length_mm >= 0.0)) {
    return fail("correlation_length_mm must be >= 0 (0 = automatic)");
  }
  if (!(std::isfinite(prior_mu_std_floor) && prior_mu_std_floor >= 0.0)) return fail("prior_mu_std_floor must be >= 0");
  if (!(min_mu_se > 0.0 && min_spread > 0.0)) return fail("min_mu_se and min_spread must be > 0");
  if (!(std::isfinite(min_end_piece_mark_mm) && min_end_piece_mark_mm >= 0.0)) {
    return fail("min_end_piece_mark_mm must be >= 0");
  }
  if (!(std::isfinite(max_transition_piece_mm) && max_transition_piece_mm >= 0.0)) {
    return fail("max_transition_piece_mm must be >= 0");
  }
  if (!(std::isfinite(end_piece_mark_z) && end_piece_mark_z >= 0.0)) return fail("end_piece_mark_z must be >= 0");
  if (!(std::isfinite(change_location_mm) && change_location_mm >= 0.0)) return fail("change_location_mm must be >= 0");
  if (!(std::isfinite(near_data_mm) && near_data_mm >= 0.0)) return fail("near_data_mm must be >= 0 (0 = automatic)");
  return true;
}

absl::StatusOr<RegionMap> RegionMap::Create(const SurfaceLevel& level, const RegionMapOptions& options) {
  std::string why;
  if (!options.IsValid(&why)) return absl::InvalidArgumentError(absl::StrCat("RegionMapOptions: ", why));
  const std::size_t nv = level.limit_positions.size();
  if (nv == 0 || level.triangles.empty()) return absl::InvalidArgumentError("RegionMap: the level has no vertices or triangles");
  if (level.neighbors.size() != nv || level.limit_normals.size() != nv) {
    return absl::InvalidArgumentError(absl::StrCat("RegionMap: the level has ", nv, " limit positions but ",
                                                   level.neighbors.size(), " neighbour rows and ",
                                                   level.limit_normals.size(), " normals"));
  }
  for (std::size_t t = 0; t < level.triangles.size(); ++t) {
    for (int v : level.triangles[t]) {
      if (v < 0 || static_cast<std::size_t>(v) >= nv) {
        return absl::InvalidArgumentError(absl::StrCat("RegionMap: triangle ", t, " names vertex ", v, ", outside 0..", nv - 1));
      }
    }
  }
  RegionMap map;
  map.level_ = &level;
  map.options_ = options;
  map.locator_ = std::make_shared<const MeshLocator>(level);
  absl::StatusOr<LabelPropagation> propagation = LabelPropagation::Create(level);
  if (!propagation.ok()) return propagation.status();
  map.propagation_ = std::make_shared<LabelPropagation>(*std::move(propagation));
  map.correlation_length_mm_ = options.correlation_length_mm;
  map.near_data_mm_ = options.near_data_mm;
  if (map.near_data_mm_ == 0.0) {
    std::vector<double> lengths;
    for (const auto& e : level.edges) lengths.push_back((level.limit_positions[e[0]] - level.limit_positions[e[1]]).norm());
    if (!lengths.empty()) {
      std::nth_element(lengths.begin(), lengths.begin() + lengths.size() / 2, lengths.end());
      map.near_data_mm_ = lengths[lengths.size() / 2];
    }
  }
  if (map.correlation_length_mm_ == 0.0) {
    Eigen::Vector3d lo = level.limit_positions[0], hi = lo;
    for (const auto& p : level.limit_positions) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
    map.correlation_length_mm_ = std::max(0.1 * (hi - lo).norm(), 1e-9);
  }
  return map;
}

absl::Status RegionMap::Validate(const std::vector<MapPiece>& pieces) const {
  if (pieces.empty()) return absl::InvalidArgumentError("RegionMap::SetPieces: no pieces");
  for (std::size_t i = 0; i < pieces.size(); ++i) {
    const MapPiece& p = pieces[i];
    auto bad = [i](const std::string& what) {
      return absl::InvalidArgumentError(absl::StrCat("map piece ", i, ": ", what));
    };
    if (p.points.empty()) return bad("has no points");
    for (std::size_t k = 0; k < p.points.size(); ++k) {
      if (!p.points[k].allFinite()) return bad(absl::StrCat("point ", k, " is not finite"));
    }
    if (!p.pair_mu.empty() && p.point_s_mm.empty()) return bad("has a pair series but no point positions");
    if (!p.point_s_mm.empty() && p.point_s_mm.size() != p.points.size()) {
      return bad(absl::StrCat(p.point_s_mm.size(), " point positions but ", p.points.size(), " points"));
    }
    for (std::size_t k = 1; k < p.point_s_mm.size(); ++k) {
      if (!(p.point_s_mm[k] >= p.point_s_mm[k - 1])) return bad(absl::StrCat("point position ", k, " is not increasing"));
    }
    LineSample probe;
    probe.pair_s_mm = p.pair_s_mm;  // the pair series by the line sample's rules
    probe.pair_mu = p.pair_mu;
    probe.path_s_mm = {p.piece.start_mm, p.piece.end_mm};
    probe.path_points = {p.points.front(), p.points.back()};
    probe.pieces = {p.piece};
    if (absl::Status s = probe.Validate(); !s.ok()) {
      return bad(std::string(absl::StripPrefix(absl::StripPrefix(s.message(), "line sample: piece 0: "), "line sample: ")));
    }
  }
  return absl::OkStatus();
}

RegionMap::PlacedPiece RegionMap::Place(const MapPiece& piece, int index) const {
  PlacedPiece placed;
  placed.points = piece.points;
  for (const Eigen::Vector3d& point : Resample(piece.points, options_.point_spacing_mm)) {
    const SurfacePoint hit = locator_->Closest(point);
    if (hit.triangle < 0) continue;
    for (int corner : level_->triangles[hit.triangle]) placed.seeds.push_back({hit.position, corner, index});
    placed.surface_seeds.push_back({hit.triangle, hit.barycentric, index});
    placed.data_points.push_back(hit.position);
  }
  return placed;
}

absl::Status RegionMap::SetPieces(std::vector<MapPiece> pieces) {
  if (absl::Status s = Validate(pieces); !s.ok()) return s;
  std::vector<PlacedPiece> placed;
  placed.reserve(pieces.size());
  for (std::size_t i = 0; i < pieces.size(); ++i) {
    if (i < given_placed_.size() && given_placed_[i].points == pieces[i].points) {
      placed.push_back(std::move(given_placed_[i]));
    } else {
      placed.push_back(Place(pieces[i], static_cast<int>(i)));
    }
  }
  given_placed_ = std::move(placed);
  split_pieces_ = 0;
  materials_dissolved_ = 0;
  parts_placed_.clear();
  pieces_ = std::move(pieces);
  if (absl::Status s = GroupPieces(); !s.ok()) return s;
  if (!options_.split_against_materials) return SpreadRegions();

  // Test every piece again against the materials just found, and build the
  // map again from the split pieces where any was split. The pieces of a
  // dissolved material hold two materials each: they take no part in the
  // textures.
  std::vector<int> piece_material(pieces_.size());
  for (std::size_t i = 0; i < pieces_.size(); ++i) {
    piece_material[i] = of_dissolved_material_[i] ? -1 : regions_[piece_region_[i]].material;
  }
  const std::vector<SeriesTexture> textures =
      FittedTextures(MaterialTextures(pieces_, piece_material, options_.min_texture_rows));
  absl::StatusOr<std::vector<std::vector<MapPiece>>> found = SplitPiecesAgainst(pieces_, textures, options_.known_split);
  if (!found.ok()) return found.status();  // SetPieces validated the pieces: a broken invariant
  std::vector<std::vector<MapPiece>>& splits = *found;
  if (std::all_of(splits.begin(), splits.end(), [](const auto& s) { return s.empty(); })) return SpreadRegions();
  std::vector<MapPiece> split_pieces;
  std::vector<PlacedPiece> split_placed;
  for (std::size_t i = 0; i < pieces_.size(); ++i) {
    if (splits[i].empty()) {
      PlacedPiece p = given_placed_[i];
      const int index = static_cast<int>(split_pieces.size());
      for (LabelledSeed& seed : p.seeds) seed.label = index;
      for (SurfaceSeed& seed : p.surface_seeds) seed.label = index;
      split_placed.push_back(std::move(p));
      split_pieces.push_back(std::move(pieces_[i]));
      continue;
    }
    for (MapPiece& sub : splits[i]) {
      split_placed.push_back(Place(sub, static_cast<int>(split_pieces.size())));
      split_pieces.push_back(std::move(sub));
    }
  }
  pieces_ = std::move(split_pieces);
  parts_placed_ = std::move(split_placed);
  split_pieces_ = static_cast<int>(std::count_if(splits.begin(), splits.end(), [](const auto& s) { return !s.empty(); }));
  if (absl::Status s = GroupPieces(); !s.ok()) return s;
  return SpreadRegions();
}

absl::Status RegionMap::SetPendingPoints(std::vector<Eigen::Vector3d> points) {
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (!points[i].allFinite()) {
      return absl::InvalidArgumentError(absl::StrCat("RegionMap::SetPendingPoints: point ", i, " is not finite"));
    }
  }
  pending_ = std::move(points);
  if (has_pieces()) RecomputeUncertainty();
  return absl::OkStatus();
}

void RegionMap::Summarise(const std::vector<int>& piece_indices, const std::vector<PieceStatistics>& statistics,
                          int order, const std::vector<int>& better_material, TextureRegion* out) const {
  // A piece of a dissolved material straddles a boundary and reads between
  // two materials: like a misfit, it counts in no mu.
  auto misfit = [&](int i) {
    return (options_.exclude_misfit_pieces_from_mu && better_material[i] >= 0) || of_dissolved_material_[i];
  };
  // Misfits count only when nothing else would.
  const bool any_fits = std::any_of(piece_indices.begin(), piece_indices.end(), [&](int i) { return !misfit(i); });
  std::vector<PieceStatistics> members, long_pieces;
  std::vector<int> member_indices, long_indices;
  std::vector<std::vector<double>> k(order);
  std::vector<double> log_sigma;
  for (int i : piece_indices) {
    const bool counts = !any_fits || !misfit(i);
    if (counts) {
      members.push_back(statistics[i]);
      member_indices.push_back(i);
    }
    const LinePiece& piece = pieces_[i].piece;
    const TextureParams& t = piece.texture;
    const bool long_enough = options_.min_mu_piece_mm > 0.0 ? piece.end_mm - piece.start_mm >= options_.min_mu_piece_mm
                                                            : piece.has_roughness();
    if (long_enough && counts) {
      long_pieces.push_back(statistics[i]);
      long_indices.push_back(i);
    }
    if (!piece.has_roughness()) continue;
    for (int j = 0; j < order; ++j) k[j].push_back(j < static_cast<int>(t.reflection.size()) ? t.reflection[j] : 0.0);
    log_sigma.push_back(std::log(t.sigma));
  }
  const int min_fitted = options_.min_fitted_pieces_for_mu;
  const bool from_long = min_fitted > 0 && static_cast<int>(long_pieces.size()) >= min_fitted;
  out->statistics = PoolStatistics(from_long ? long_pieces : members);
  out->mu_pieces = from_long ? long_indices : member_indices;
  out->roughness_pieces = static_cast<int>(log_sigma.size());
  if (out->roughness_pieces > 0) {
    for (int j = 0; j < order; ++j) out->reflection.push_back(std::clamp(Median(k[j]), -kMaxReflection, kMaxReflection));
    out->sigma = std::exp(Median(log_sigma));
  }
}

std::vector<int> RegionMap::Materials(const std::vector<PieceStatistics>& own) const {
  const int region_count = static_cast<int>(own.size());
  std::vector<int> material(region_count);
  std::iota(material.begin(), material.end(), 0);
  if (!options_.pool_alike_regions) return material;
  // Regions are grown only between pieces that touch, so one material met
  // in several places (a band that pieces straddling its neighbour cut into
  // stretches, patches of one material far apart) makes several regions,
  // each estimated from its own few pieces: on twin_band_egg the masonite
  // band's stretches read 0.324-0.361 (truth 0.36) while the rubber band
  // beside it read 0.290-0.317. Regions alike by the merge rule, wherever
  // they lie, are one material: the same greedy merging, misfits moved,
  // with every pair of regions as neighbours.
  std::vector<std::pair<int, int>> every_pair;
  for (int a = 0; a < region_count; ++a) {
    for (int b = a + 1; b < region_count; ++b) every_pair.emplace_back(a, b);
  }
  return MergeIntoRegions(own, every_pair, {}, options_.merge);
}

std::vector<int> RegionMap::AssignByTexture(const std::vector<PieceStatistics>& own, std::vector<int> material,
                                            std::vector<std::optional<SeriesTexture>>* fitted) {
  const int n = static_cast<int>(pieces_.size());
  const int region_count = static_cast<int>(own.size());
  std::vector<int> piece_material(n);
  for (int i = 0; i < n; ++i) piece_material[i] = material[piece_region_[i]];
  std::vector<std::vector<int>> region_pieces(region_count);
  for (int r = 0; r < region_count; ++r) region_pieces[r] = regions_[r].pieces;
  const int materials = region_count == 0 ? 0 : *std::max_element(material.begin(), material.end()) + 1;
  std::vector<std::vector<PieceStatistics>> members(materials);
  for (int r = 0; r < region_count; ++r) members[material[r]].push_back(own[r]);
  std::vector<PieceStatistics> pooled(materials);
  for (int m = 0; m < materials; ++m) pooled[m] = PoolStatistics(members[m]);
  auto may_join = [&](int r, int m) { return TexturesAlike(own[r], pooled[m], options_.merge); };
  *fitted = MaterialTextures(pieces_, piece_material, options_.min_texture_rows);
  TextureAssignment assigned = AssignRegionsByTexture(pieces_, region_pieces, material, *fitted, may_join,
                                                      options_.known_split.false_alarm_probability);
  regions_moved_by_texture_ = assigned.moved;
  return std::move(assigned.material);
}

std::vector<int> RegionMap::MisfitPieces(const std::vector<int>& piece_material,
                                         std::vector<std::optional<SeriesTexture>> textures) const {
  const int n = static_cast<int>(pieces_.size());
  std::vector<int> better(n, -1);
  if (!options_.exclude_misfit_pieces_from_mu && !options_.move_misfit_pieces) return better;
  if (textures.empty()) textures = MaterialTextures(pieces_, piece_material, options_.min_texture_rows);
  std::vector<int> textured;
  for (int m = 0; m < static_cast<int>(textures.size()); ++m) {
    if (textures[m].has_value()) textured.push_back(m);
  }
  if (textured.size() < 2) return better;
  // As for a region (texture_assignment.h): each likelihood ratio has
  // expectation 1 under the piece's own texture; Markov and the union bound.
  const double critical =
      std::log(static_cast<double>(textured.size() - 1) / options_.known_split.false_alarm_probability);
  for (int i = 0; i < n; ++i) {
    const int own = piece_material[i];
    const std::vector<double>& x = pieces_[i].pair_mu;
    if (own < 0 || own >= static_cast<int>(textures.size()) || !textures[own].has_value() || x.size() < 3) continue;
    double best = SeriesLogLikelihood(x, *textures[own]) + critical;
    for (int m : textured) {
      if (m == own) continue;
      const double log_likelihood = SeriesLogLikelihood(x, *textures[m]);
      if (log_likelihood > best) best = log_likelihood, better[i] = m;
    }
  }
  return better;
}

absl::StatusOr<int> RegionMap::DissolveMixtureMaterials(std::vector<int>* region_material,
                                                        std::vector<std::optional<SeriesTexture>>* textures,
                                                        std::vector<int>* piece_material) {
  absl::StatusOr<std::vector<int>> dissolved =
      MixtureMaterials(pieces_, *piece_material, *textures, options_.known_split);
  if (!dissolved.ok()) return dissolved.status();
  if (dissolved->empty()) return 0;
  const int materials = static_cast<int>(textures->size());
  std::vector<bool> gone(materials, false);
  for (int m : *dissolved) gone[m] = true;
  std::vector<int>& material = *region_material;
  for (int r = 0; r < static_cast<int>(material.size()); ++r) {
    if (!gone[material[r]]) continue;
    const std::vector<int>& members = regions_[r].pieces;
    const bool has_series =
        std::any_of(members.begin(), members.end(), [&](int i) { return pieces_[i].pair_mu.size() >= 3; });
    double region_mu = 0.0;
    for (int i : members) region_mu += pieces_[i].piece.texture.mu / members.size();
    // The material whose texture explains the region's series best, or, for
    // a region without a series, whose texture's mean is nearest its mu (a
    // dissolved material always leaves at least two with a texture).
    int best = -1;
    double best_score = -std::numeric_limits<double>::infinity();
    for (int m = 0; m < materials; ++m) {
      if (gone[m] || !(*textures)[m].has_value()) continue;
      const double score = has_series ? RegionLogLikelihood(pieces_, members, *(*textures)[m])
                                      : -std::abs((*textures)[m]->mean - region_mu);
      if (score > best_score) best_score = score, best = m;
    }
    material[r] = best;
    for (int i : members) of_dissolved_material_[i] = true;
  }
  std::vector<std::optional<SeriesTexture>> kept;
  for (int old : RenumberInOrderOfFirstRegion(&material)) kept.push_back((*textures)[old]);
  *textures = std::move(kept);
  for (std::size_t i = 0; i < pieces_.size(); ++i) (*piece_material)[i] = material[piece_region_[i]];
  return static_cast<int>(dissolved->size());
}

int RegionMap::MoveMisfitPieces(const std::vector<PieceStatistics>& statistics, std::vector<int>* better_material,
                                std::vector<int>* region_material, std::vector<PieceStatistics>* own,
                                std::vector<int>* piece_material) {
  std::vector<int>& better = *better_material;
  int moved = 0;
  const int region_count = static_cast<int>(regions_.size());
  // Each material's pieces pooled, for the merge rule's test.
  std::vector<PieceStatistics> pooled;
  if (options_.move_only_to_alike_material) {
    const int n = static_cast<int>(pieces_.size());
    std::vector<std::vector<PieceStatistics>> members;
    for (int i = 0; i < n; ++i) {
      const int m = (*piece_material)[i];
      if (m < 0) continue;
      if (m >= static_cast<int>(members.size())) members.resize(m + 1);
      members[m].push_back(statistics[i]);
    }
    for (const auto& of_material : members) pooled.push_back(PoolStatistics(of_material));
  }
  auto moves = [&](int i) {
    if (better[i] < 0) return false;
    if (pooled.empty()) return true;
    return better[i] < static_cast<int>(pooled.size()) && TexturesAlike(statistics[i], pooled[better[i]], options_.merge);
  };
  for (int r = 0; r < region_count; ++r) {
    std::vector<int> fitting, misfits;
    for (int i : regions_[r].pieces) (moves(i) ? misfits : fitting).push_back(i);
    // A region all of misfits stays as it is: assign_by_texture tests the
    // region as a whole, and its pieces are left out of the mu.
    if (fitting.empty() || misfits.empty()) continue;
    regions_[r].pieces = fitting;
    std::vector<PieceStatistics> members;
    for (int i : fitting) members.push_back(statistics[i]);
    (*own)[r] = PoolStatistics(members);
    for (int i : misfits) {
      piece_region_[i] = static_cast<int>(regions_.size());
      TextureRegion region;
      region.pieces = {i};
      regions_.push_back(std::move(region));
      region_material->push_back(better[i]);
      own->push_back(statistics[i]);
      (*piece_material)[i] = better[i];
      ++moved;
    }
  }
  return moved;
}

absl::Status RegionMap::GroupPieces() {
  const int n = static_cast<int>(pieces_.size());
  const int nv = vertex_count();
  std::vector<LabelledSeed> seeds;
  for (const PlacedPiece& p : placed()) seeds.insert(seeds.end(), p.seeds.begin(), p.seeds.end());

  // Which pieces touch: Voronoi cells that meet across an edge, the two
  // nearest pieces of a vertex, and neighbours along one drag.
  const NearestLabels by_piece = FindNearestLabels(*level_, seeds);
  std::vector<std::pair<int, int>> adjacent, cannot_link;
  for (const auto& e : level_->edges) {
    const int a = by_piece.label[e[0]][0], b = by_piece.label[e[1]][0];
    if (a >= 0 && b >= 0 && a != b) adjacent.emplace_back(std::min(a, b), std::max(a, b));
  }
  for (int v = 0; v < nv; ++v) {
    const int a = by_piece.label[v][0], b = by_piece.label[v][1];
    if (a >= 0 && b >= 0) adjacent.emplace_back(std::min(a, b), std::max(a, b));
  }
  for (int i = 0; i + 1 < n; ++i) {
    if (pieces_[i].drag != pieces_[i + 1].drag) continue;
    adjacent.emplace_back(i, i + 1);
    if (pieces_[i].piece.ends_at_change) cannot_link.emplace_back(i, i + 1);
  }
  std::sort(adjacent.begin(), adjacent.end());
  adjacent.erase(std::unique(adjacent.begin(), adjacent.end()), adjacent.end());

  std::vector<PieceStatistics> statistics(n);
  for (int i = 0; i < n; ++i) {
    const LinePiece& p = pieces_[i].piece;
    statistics[i].mu = p.texture.mu;
    double se2 = std::max(p.mu_se, options_.min_mu_se) * std::max(p.mu_se, options_.min_mu_se);
    // The part of a neighbour across a change that may be inside the piece.
    const double length = std::max(p.end_mm - p.start_mm, options_.change_location_mm);
    for (int side : {-1, 1}) {
      const int j = i + side;
      const bool bounded = side < 0 ? p.starts_at_change : p.ends_at_change;
      if (!bounded || j < 0 || j >= n || pieces_[j].drag != pieces_[i].drag) continue;
      const double share = std::min(1.0, options_.change_location_mm / length);
      const double jump = pieces_[j].piece.texture.mu - p.texture.mu;
      se2 += share * share * jump * jump;
    }
    statistics[i].mu_se = std::sqrt(se2);
    statistics[i].spread = std::max(p.texture.mu_std, options_.min_spread);
    statistics[i].effective_pairs = std::max(p.effective_pairs, 1.0);
    if (p.has_roughness() && p.roughness_rows > 0) {
      const int order = std::min<int>(p.texture.reflection.size(), PieceStatistics::kMaxSignatureOrder);
      statistics[i].signature_order = order;
      for (int j = 0; j < order; ++j) {
        statistics[i].reflection[j] = p.texture.reflection[j];
        statistics[i].reflection_rows[j] = p.roughness_rows;
      }
    }
  }
  piece_region_ = MergeIntoRegions(statistics, adjacent, cannot_link, options_.merge);
  int region_count = n == 0 ? 0 : *std::max_element(piece_region_.begin(), piece_region_.end()) + 1;
  regions_.assign(region_count, {});
  int order = 0;
  for (int i = 0; i < n; ++i) {
    regions_[piece_region_[i]].pieces.push_back(i);
    if (pieces_[i].piece.has_roughness()) order = std::max<int>(order, pieces_[i].piece.texture.reflection.size());
  }
  // Each region's own pool, its material, and the material's estimates
  // (from all its pieces) as the region's.
  std::vector<PieceStatistics> own(region_count);
  for (int r = 0; r < region_count; ++r) {
    std::vector<PieceStatistics> members;
    for (int i : regions_[r].pieces) members.push_back(statistics[i]);
    own[r] = PoolStatistics(members);
  }
  regions_moved_by_texture_ = 0;
  std::vector<int> material = Materials(own);
  // The materials' textures, kept for the misfit test when the assignment
  // moved no region and kept the numbering: the same pieces make the same
  // materials, and fitting them twice cost 5 % of a rebuild.
  std::vector<std::optional<SeriesTexture>> textures;
  if (options_.assign_by_texture) {
    std::vector<int> assigned = AssignByTexture(own, material, &textures);
    if (assigned != material) textures.clear();
    material = std::move(assigned);
  }
  std::vector<int> piece_material(n);
  for (int i = 0; i < n; ++i) piece_material[i] = material[piece_region_[i]];
  of_dissolved_material_.assign(n, false);
  if (options_.dissolve_mixture_materials) {
    if (textures.empty()) textures = MaterialTextures(pieces_, piece_material, options_.min_texture_rows);
    absl::StatusOr<int> dissolved = DissolveMixtureMaterials(&material, &textures, &piece_material);
    if (!dissolved.ok()) return dissolved.status();  // SetPieces validated the pieces: a broken invariant
    materials_dissolved_ += *dissolved;
  }
  const int material_count = region_count == 0 ? 0 : *std::max_element(material.begin(), material.end()) + 1;
  std::vector<int> better_material = MisfitPieces(piece_material, std::move(textures));
  pieces_moved_by_texture_ =
      options_.move_misfit_pieces ? MoveMisfitPieces(statistics, &better_material, &material, &own, &piece_material) : 0;
  region_count = static_cast<int>(regions_.size());
  std::vector<std::vector<int>> material_pieces(material_count);
  for (int r = 0; r < region_count; ++r) {
    const std::vector<int>& p = regions_[r].pieces;
    material_pieces[material[r]].insert(material_pieces[material[r]].end(), p.begin(), p.end());
  }
  std::vector<TextureRegion> estimates(material_count);
  for (int m = 0; m < material_count; ++m) Summarise(material_pieces[m], statistics, order, better_material, &estimates[m]);
  for (int r = 0; r < region_count; ++r) {
    TextureRegion& region = regions_[r];
    const TextureRegion& of_material = estimates[material[r]];
    region.material = material[r];
    region.own_statistics = own[r];
    region.statistics = of_material.statistics;
    region.mu_pieces = of_material.mu_pieces;
    region.roughness_pieces = of_material.roughness_pieces;
    region.reflection = of_material.reflection;
    region.sigma = of_material.sigma;
  }
  piece_statistics_ = std::move(statistics);
  return absl::OkStatus();
}

absl::Status RegionMap::SpreadRegions() {
  const int n = static_cast<int>(pieces_.size());
  const int nv = vertex_count();
  std::vector<LabelledSeed> seeds;
  for (const PlacedPiece& p : placed()) seeds.insert(seeds.end(), p.seeds.begin(), p.seeds.end());
  const int region_count = static_cast<int>(regions_.size());
  int order = 0;
  for (const MapPiece& p : pieces_) {
    if (p.piece.has_roughness()) order = std::max<int>(order, p.piece.texture.reflection.size());
  }

  // The region diagram.
  seed_points_.clear();
  for (LabelledSeed& s : seeds) {
    s.label = piece_region_[s.label];
    seed_points_.push_back(s.point);
  }
  nearest_ = FindNearestLabels(*level_, seeds);
  double mean = 0.0;
  for (const MapPiece& p : pieces_) mean += p.piece.texture.mu;
  mean /= n;
  double var = 0.0;
  for (const MapPiece& p : pieces_) var += (p.piece.texture.mu - mean) * (p.piece.texture.mu - mean);
  var /= std::max(1, n - 1);
  prior_mu_std_ = std::max(std::sqrt(var), options_.prior_mu_std_floor);

  // Regions spread from their pieces' points.
  std::vector<SurfaceSeed> surface_seeds;
  for (const PlacedPiece& p : placed()) {
    for (SurfaceSeed s : p.surface_seeds) {
      s.label = piece_region_[s.label];
      surface_seeds.push_back(s);
    }
  }
  // Boundaries through neighbouring crossings, of materials or of regions.
  std::vector<int> side(n);
  for (int i = 0; i < n; ++i) {
    side[i] = options_.link_materials ? regions_[piece_region_[i]].material : piece_region_[i];
  }
  std::vector<char> transition(n, 0);
  for (int i = 0; options_.transition_pieces_mark_one_crossing && i < n; ++i) transition[i] = TransitionPiece(i, side);
  std::vector<ChangeMark> marks;
  for (int i = 0; i + 1 < n; ++i) {
    if (transition[i]) continue;
    // Across transitions (a run of them, where the detector cut a step
    // more than twice) the crossing is from the piece before them to the
    // piece after them, halfway along them (a transition has a piece after
    // it in its drag: TransitionPiece).
    int next = i + 1;
    std::vector<Eigen::Vector3d> across;
    for (; transition[next]; ++next) across.insert(across.end(), pieces_[next].points.begin(), pieces_[next].points.end());
    const MapPiece& a = pieces_[i];
    const MapPiece& b = pieces_[next];
    if (a.drag != b.drag || !a.piece.ends_at_change || side[i] == side[next]) continue;
    if (a.points.size() < 2 || b.points.size() < 2) continue;
    if (UnconfirmedEndPiece(a, b) || UnconfirmedEndPiece(b, a)) continue;
    ChangeMark m;
    const SurfacePoint hit = locator_->Closest(across.empty() ? b.points.front() : HalfwayAlong(across));
    m.position = hit.position;
    m.normal = hit.normal;
    Eigen::Vector3d direction = b.points[1] - a.points[a.points.size() - 2];
    direction -= direction.dot(m.normal) * m.normal;
    if (direction.norm() < 1e-9) continue;
    m.direction = direction.normalized();
    m.before = side[i];
    m.after = side[next];
    m.drag = a.drag;
    marks.push_back(m);
  }
  std::vector<LabelledPoint> data;
  for (int i = 0; i < n; ++i) {
    for (const Eigen::Vector3d& p : placed()[i].data_points) data.push_back({p, piece_region_[i]});
  }
  links_ = 0;
  corners_ = 0;
  bridges_ = 0;
  dots_ = 0;
  rectangles_ = 0;
  marks_ = std::move(marks);
  // The links check their corridors against every piece's data but an
  // unconfirmed end piece's (boundaries_ignore_unconfirmed_end_pieces) and
  // a transition's (transition_pieces_mark_one_crossing), by material when
  // they link materials. The plan's map (rebuilt after every drag) links
  // regions with every piece and copies nothing.
  const bool skip_unconfirmed = options_.boundaries_ignore_unconfirmed_end_pieces;
  const bool own_link_data = options_.link_materials || skip_unconfirmed || options_.transition_pieces_mark_one_crossing;
  std::vector<LabelledPoint> link_data;
  for (int i = 0; own_link_data && i < n; ++i) {
    if ((skip_unconfirmed && UnconfirmedEndPiece(i)) || transition[i]) continue;
    for (const Eigen::Vector3d& p : placed()[i].data_points) link_data.push_back({p, side[i]});
  }
  const std::vector<LabelledPoint> link_points = BoundaryLinkPoints(marks_, own_link_data ? link_data : data,
                                                                    options_.links, &links_, &corners_, &bridges_, &dots_,
                                                                    &rectangles_);
  // The region of `material` whose data lies nearest a link point: searched
  // in growing boxes, since a link's middle can lie a link's length from its
  // ends.
  constexpr double kRegionSearchCellMm = 4.0;
  const LabelledPointGrid region_data(
      options_.link_materials && !link_points.empty() ? data : std::vector<LabelledPoint>{}, kRegionSearchCellMm);
  auto nearest_region_of_material = [&](const Eigen::Vector3d& point, int material) {
    for (double reach = kRegionSearchCellMm; reach <= 4.0 * options_.links.max_length_mm; reach *= 2.0) {
      int best = -1;
      double best_d2 = std::numeric_limits<double>::infinity();
      region_data.ForEachNear(point, point, reach, [&](const LabelledPoint& x) {
        const double d2 = (x.point - point).squaredNorm();
        if (regions_[x.label].material == material && d2 < best_d2) best_d2 = d2, best = x.label;
      });
      if (best >= 0) return best;
    }
    return -1;
  };
  for (const LabelledPoint& p : link_points) {
    const bool along = !p.project_along.isZero();
    const SurfacePoint hit = along ? locator_->ClosestAlong(p.point, p.project_along) : locator_->Closest(p.point);
    if (hit.triangle < 0) continue;
    const Eigen::Vector3d at = along ? hit.position : p.point;
    const int region = options_.link_materials ? nearest_region_of_material(at, p.label) : p.label;
    if (region < 0) continue;
    surface_seeds.push_back({hit.triangle, hit.barycentric, region});
    data.push_back({hit.position, region});
  }
  near_data_ = near_data_mm_ > 0.0 ? LabelledPointGrid(std::move(data), near_data_mm_) : LabelledPointGrid();
  absl::StatusOr<std::vector<std::vector<double>>> fields = propagation_->Propagate(surface_seeds, region_count);
  if (!fields.ok()) return fields.status();
  probability_ = *std::move(fields);

  region_.assign(nv, -1);
  second_region_.assign(nv, -1);
  mu_.assign(nv, mean);
  boundary_probability_.assign(nv, 0.0);
  reflection_.assign(order, std::vector<double>(nv, kNaN));
  log_sigma_.assign(order > 0 ? nv : 0, kNaN);
  for (int v = 0; v < nv; ++v) {
    int r = -1, second = -1;
    double pr = 0.0, p2 = 0.0;
    for (int c = 0; c < region_count; ++c) {
      const double p = probability_[c][v];
      if (p > pr) {
        second = r, p2 = pr;
        r = c, pr = p;
      } else if (p > p2) {
        second = c, p2 = p;
      }
    }
    if (r < 0) continue;  // no data reaches this part of the surface
    region_[v] = r;
    second_region_[v] = second;
    mu_[v] = regions_[r].statistics.mu;
    if (second >= 0) boundary_probability_[v] = p2 / (pr + p2);
    if (regions_[r].has_roughness()) {
      for (int j = 0; j < order; ++j) reflection_[j][v] = regions_[r].reflection[j];
      log_sigma_[v] = std::log(regions_[r].sigma);
    }
  }
  RecomputeUncertainty();
  return absl::OkStatus();
}

double RegionMap::BoundaryVariance(int region, int second, double p) const {
  if (region < 0 || second < 0) return 0.0;
  const double jump = regions_[second].statistics.mu - regions_[region].statistics.mu;
  return p * (1.0 - p) * jump * jump;
}

bool RegionMap::UnconfirmedEndPiece(int i) const {
  const int n = static_cast<int>(pieces_.size());
  const int drag = pieces_[i].drag;
  return (i > 0 && pieces_[i - 1].drag == drag && UnconfirmedEndPiece(pieces_[i], pieces_[i - 1])) ||
         (i + 1 < n && pieces_[i + 1].drag == drag && UnconfirmedEndPiece(pieces_[i], pieces_[i + 1]));
}

bool RegionMap::TransitionPiece(int i, const std::vector<int>& side) const {
  const int n = static_cast<int>(pieces_.size());
  if (i <= 0 || i + 1 >= n) return false;
  const MapPiece& t = pieces_[i];
  const MapPiece& before = pieces_[i - 1];
  const MapPiece& after = pieces_[i + 1];
  if (before.drag != t.drag || after.drag != t.drag || t.points.empty()) return false;
  if (!(t.piece.starts_at_change && t.piece.ends_at_change)) return false;
  if (!(t.piece.end_mm - t.piece.start_mm < options_.max_transition_piece_mm)) return false;
  if (side[i] == side[i - 1] || side[i] == side[i + 1] || side[i - 1] == side[i + 1]) return false;
  const double lo = std::min(before.piece.texture.mu, after.piece.texture.mu);
  const double hi = std::max(before.piece.texture.mu, after.piece.texture.mu);
  const double slack = options_.end_piece_mark_z * t.piece.mu_se;
  return t.piece.texture.mu > lo - slack && t.piece.texture.mu < hi + slack;
}

bool RegionMap::UnconfirmedEndPiece(const MapPiece& end, const MapPiece& other) const {
  const LinePiece& p = end.piece;
  const bool at_window_end = !(p.starts_at_change && p.ends_at_change);  // one side is the drag's window end
  if (!at_window_end || !(p.end_mm - p.start_mm < options_.min_end_piece_mark_mm)) return false;
  const double se = std::hypot(p.mu_se, other.piece.mu_se);
  return std::abs(p.texture.mu - other.piece.texture.mu) < options_.end_piece_mark_z * se;
}

double RegionMap::ConfusionCost(int a, int b, const TextureDistanceOptions& metric) const {
  const int n = static_cast<int>(regions_.size());
  if (a < 0 || b < 0 || a >= n || b >= n) return 0.0;
  const TextureRegion& x = regions_[a];
  const TextureRegion& y = regions_[b];
  const double jump = y.statistics.mu - x.statistics.mu;
  if (metric.property == TextureProperty::kFriction || !x.has_roughness() || !y.has_roughness()) return jump * jump;
  const double d = metric.mu_scale * TextureDistance({x.statistics.mu, 0.0, x.reflection, x.sigma},
                                                     {y.statistics.mu, 0.0, y.reflection, y.sigma}, metric);
  return d * d;  // finite: the regions' estimates are, and a plan's metric is validated
}

double RegionMap::PriorTextureVariance(const TextureDistanceOptions& metric) const {
  const double friction = prior_mu_std_ * prior_mu_std_;
  if (metric.property == TextureProperty::kFriction) return friction;
  const double roughness = RoughnessVariance(pieces_, metric);
  if (metric.property == TextureProperty::kRoughness) return roughness > 0.0 ? roughness : friction;
  return friction + roughness;
}

double RegionMap::FarVariance(double d) const {
  return prior_mu_std_ * prior_mu_std_ * -std::expm1(-2.0 * d / correlation_length_mm_);
}

double RegionMap::PointVariance(int region, int second, double p, double d) const {
  if (region < 0) return prior_mu_std_ * prior_mu_std_;
  const double se = regions_[region].statistics.mu_se;
  return se * se + FarVariance(d) + BoundaryVariance(region, second, p);
}

void RegionMap::RecomputeUncertainty() {
  const int nv = vertex_count();
  std::vector<double> pending_distance(nv, kInf);
  if (!pending_.empty()) {
    std::vector<LabelledSeed> seeds;
    for (const Eigen::Vector3d& p : pending_) {
      const SurfacePoint hit = locator_->Closest(p);
      if (hit.triangle < 0) continue;
      for (int corner : level_->triangles[hit.triangle]) seeds.push_back({hit.position, corner, 0});
    }
    const NearestLabels near = FindNearestLabels(*level_, seeds);
    for (int v = 0; v < nv; ++v) pending_distance[v] = near.distance_mm[v][0];
  }
  data_distance_mm_.assign(nv, kInf);
  mu_std_.assign(nv, prior_mu_std_);
  boundary_variance_.assign(nv, 0.0);
  far_variance_.assign(nv, prior_mu_std_ * prior_mu_std_);
  for (int v = 0; v < nv; ++v) {
    data_distance_mm_[v] = std::min(nearest_.distance_mm[v][0], pending_distance[v]);
    const double d = std::isfinite(data_distance_mm_[v]) ? data_distance_mm_[v] : 1e300;
    mu_std_[v] = std::sqrt(PointVariance(region_[v], second_region_[v], boundary_probability_[v], d));
    if (region_[v] < 0) continue;
    boundary_variance_[v] = BoundaryVariance(region_[v], second_region_[v], boundary_probability_[v]);
    far_variance_[v] = FarVariance(d);
  }
}

MapValue RegionMap::VertexValue(int v) const {
  MapValue out;
  out.mu = mu_[v];
  out.mu_std = mu_std_[v];
  const int r = region_[v];
  out.region = r;
  out.has_roughness = r >= 0 && regions_[r].has_roughness();
  if (out.has_roughness) {
    out.reflection = regions_[r].reflection;
    out.sigma = regions_[r].sigma;
  }
  return out;
}

absl::StatusOr<MapValue> RegionMap::ValueAt(const SurfacePoint& point) const {
  if (!has_pieces()) return absl::FailedPreconditionError("RegionMap::ValueAt: the map has no pieces yet");
  const int nt = static_cast<int>(level_->triangles.size());
  if (point.triangle < 0 || point.triangle >= nt) {
    return absl::InvalidArgumentError(
        absl::StrCat("RegionMap::ValueAt: triangle ", point.triangle, " is outside the level's 0..", nt - 1));
  }
  if (!point.barycentric.allFinite()) {
    return absl::InvalidArgumentError("RegionMap::ValueAt: barycentric coordinates are not finite");
  }
  const auto& t = level_->triangles[point.triangle];
  const auto& x = level_->limit_positions;
  const Eigen::Vector3d& b = point.barycentric;
  int best_region = -1, second_region = -1;
  double best = 0.0, second = 0.0;
  const int near = NearestDataRegion(point.position);
  for (int c = 0; c < static_cast<int>(regions_.size()); ++c) {
    const auto& f = probability_[c];
    const double p = b[0] * f[t[0]] + b[1] * f[t[1]] + b[2] * f[t[2]];
    if (p > best) {
      second = best, second_region = best_region;
      best = p, best_region = c;
    } else if (p > second) {
      second = p, second_region = c;
    }
  }
  if (best_region < 0) return VertexValue(t[0]);
  if (near >= 0 && near != best_region) {
    second_region = best_region;
    best_region = near;
  }
  MapValue out;
  const TextureRegion& region = regions_[best_region];
  out.region = best_region;
  out.mu = region.statistics.mu;
  const double p = second_region >= 0 ? second / (best + second) : 0.0;
  double d = kInf;
  for (int i = 0; i < 3; ++i) d = std::min(d, data_distance_mm_[t[i]] + (point.position - x[t[i]]).norm());
  out.mu_std = std::sqrt(PointVariance(best_region, second_region, p, std::isfinite(d) ? d : 1e300));
  out.has_roughness = region.has_roughness();
  if (out.has_roughness) {
    out.reflection = region.reflection;
    out.sigma = region.sigma;
  }
  return out;
}

int RegionMap::NearestDataRegion(const Eigen::Vector3d& p) const {
  int best = -1;
  double best2 = near_data_mm_ * near_data_mm_;
  near_data_.ForEachNear(p, p, near_data_mm_, [&](const LabelledPoint& x) {
    const double d2 = (x.point - p).squaredNorm();
    if (d2 < best2 || (d2 == best2 && best >= 0 && x.label < best)) {
      best2 = d2;
      best = x.label;
    }
  });
  return best;
}

absl::StatusOr<MapValue> RegionMap::ValueAtPosition(const Eigen::Vector3d& position) const {
  if (!position.allFinite()) return absl::InvalidArgumentError("RegionMap::ValueAtPosition: the point is not finite");
  return ValueAt(locator_->Closest(position));
}

absl::StatusOr<std::vector<MapValue>> RegionMap::ValuesAtLevel(const SurfaceLevel& other) const {
  if (!has_pieces()) return absl::FailedPreconditionError("RegionMap::ValuesAtLevel: the map has no pieces yet");
  std::vector<MapValue> out;
  out.reserve(other.limit_positions.size());
  const bool prefix = other.limit_positions.size() <= level_->limit_positions.size() &&
                      (other.limit_positions.empty() || other.limit_positions.back() == level_->limit_positions[other.limit_positions.size() - 1]);
  for (std::size_t v = 0; v < other.limit_positions.size(); ++v) {
    if (prefix) {
      out.push_back(VertexValue(static_cast<int>(v)));
      continue;
    }
    absl::StatusOr<MapValue> value = ValueAtPosition(other.limit_positions[v]);
    if (!value.ok()) return value.status();
    out.push_back(*std::move(value));
  }
  return out;
}

Eigen::Vector3d RegionMap::NearestDataPoint(int v) const {
  if (v < 0 || v >= vertex_count()) return Eigen::Vector3d::Zero();
  const int s = nearest_.seed.empty() ? -1 : nearest_.seed[v][0];
  return s >= 0 ? seed_points_[s] : level_->limit_positions[v];
}

Eigen::Vector3d RegionMap::CrossingDirection(int v) const {
  if (v < 0 || v >= vertex_count() || second_region_.empty() || second_region_[v] < 0) return Eigen::Vector3d::Zero();
  // Least-squares gradient of g = P_2 - P_r over v's neighbours in the
  // tangent plane: it points across the boundary, towards the second region.
  const auto& x = level_->limit_positions;
  const Eigen::Vector3d& n = level_->limit_normals[v];
  Eigen::Vector3d t1 = Tangent(Eigen::Vector3d::UnitX(), n);
  if (t1.norm() < 0.1) t1 = Tangent(Eigen::Vector3d::UnitY(), n);
  t1.normalize();
  const Eigen::Vector3d t2 = n.cross(t1);
  const auto& own = probability_[region_[v]];
  const auto& other = probability_[second_region_[v]];
  const double g0 = other[v] - own[v];
  Eigen::Matrix2d normal_matrix = Eigen::Matrix2d::Zero();
  Eigen::Vector2d right = Eigen::Vector2d::Zero();
  for (int u : level_->neighbors[v]) {
    const Eigen::Vector3d d = x[u] - x[v];
    const Eigen::Vector2d q(d.dot(t1), d.dot(t2));
    normal_matrix += q * q.transpose();
    right += q * ((other[u] - own[u]) - g0);
  }
  if (std::abs(normal_matrix.determinant()) < 1e-18) return Eigen::Vector3d::Zero();
  const Eigen::Vector2d gradient = normal_matrix.ldlt().solve(right);
  const Eigen::Vector3d dir = gradient.x() * t1 + gradient.y() * t2;
  return dir.norm() > 1e-12 ? Eigen::Vector3d(dir.normalized()) : Eigen::Vector3d::Zero();
}

}  // namespace surfmap
