// The friction/roughness map from line samples: every pure piece of every
// drag (estimate/line_sample.h), placed along its executed path on the
// surface, grouped into regions of like texture with an explicit boundary
// between them. Harmonic interpolation (friction_map.h) blurs every boundary
// over the gap between samples and takes a drag as one point; here a
// boundary lies where the nearest data changes region, and a drag that found
// a change inside it pins the boundary where it crossed.
//
// Construction (SetPieces):
// 1. Each piece's points (resampled to point_spacing_mm) are projected onto
//    the map's level; the corners of the triangle holding a point are seeds.
// 2. A geodesic Voronoi diagram of the pieces (nearest_labels.h) says which
//    pieces touch; pieces that touch are merged into regions while the merged
//    groups stay statistically alike (texture_regions.h), never across a
//    detected change that is larger than the resolutions.
// 3. The regions spread over the surface from the pieces' points by a random
//    walker (label_propagation.h): each vertex gets every region's
//    probability, its region is the most probable, and the boundary passes
//    through the places where drags found changes and runs smoothly between
//    them. Inside a triangle the probabilities are interpolated linearly, so
//    the boundary is resolved below the level's edge length. A diagram of the
//    nearest data (nearest_labels.h) gives the distance to data.
//
// Values: a vertex takes its region's mu (the precision-weighted mean of its
// pieces) and, when at least one of its pieces had its own roughness fit, the
// region's roughness (per-coefficient medians of the pieces' reflection
// coefficients, median sigma): roughness comes only from pure pieces, and a
// region without one has none (NaN). Uncertainty (standard deviation of mu):
//
//   var(v) = se_r^2                          the region mean's standard error
//          + s^2 (1 - exp(-2 d / l))         far from data: d to the nearest
//                                            piece or pending point, l the
//                                            correlation length, s the spread
//                                            of the pieces' mu (floored)
//          + p (1 - p) (mu_2 - mu_r)^2       near a boundary: p = P_2 / (P_r +
//                                            P_2) from the two most probable
//                                            regions' probabilities, the chance
//                                            that v belongs to the second one,
//                                            mu_2 its mu
//
// so it rises near boundaries that no drag has pinned and far from data, and
// falls to about se_r at a piece (the random walker leaves the other regions
// a probability of ~1e-4 there).
//
// Not thread-safe for SetPieces / SetPendingPoints; the const methods may be
// called concurrently. Copies share the factorisation workspace: rebuild
// (SetPieces) only one of them.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "server/estimate/line_sample.h"
#include "server/estimate/known_texture_split.h"
#include "server/estimate/texture.h"
#include "server/map/friction_map.h"
#include "server/map/boundary_corridor.h"
#include "server/map/boundary_links.h"
#include "server/map/label_propagation.h"
#include "server/map/map_piece.h"
#include "server/map/nearest_labels.h"
#include "server/map/texture_regions.h"
#include "server/mesh/loop_surface.h"
#include "server/mesh/mesh_locator.h"

namespace surfmap {

struct RegionMapOptions {
  RegionMergeOptions merge;
  // Pieces are resampled to at most this spacing before they are placed on
  // the level: finer than the map level's edges (~1-2 mm), so every triangle
  // a piece crosses holds a seed.
  double point_spacing_mm = 0.5;
  // l above; 0 = a tenth of the level's bounding-box diagonal.
  double correlation_length_mm = 0.0;
  // Lower bound on s above: a few alike pieces must not make the whole map
  // look certain.
  double prior_mu_std_floor = 0.02;
  // Where a drag found a change, the change is located to about this much
  // (measured on the simulator: 0.04 mm between glass and rubber, 0.2-0.35 mm
  // between rough textures; FitOptions::change_guard_mm). So a piece bounded
  // by a change may hold this much of its neighbour's material: its mu
  // carries an extra error of change_location_mm / length x |mu_neighbour -
  // mu| in the merge tests (a 1.3 mm piece next to a 0.2 step: 0.046), and a
  // short end piece joins the region it belongs to instead of making one.
  double change_location_mm = 0.3;
  // Neighbouring crossings of a boundary are joined (boundary_links.h).
  BoundaryLinkOptions links;
  // Within this distance of a data point (a piece's point or a link's) the
  // map takes the nearest data point's region: the propagated
  // probabilities are linear across a triangle and cannot place a boundary
  // more finely than the level's edges, the data can. 0 = the level's
  // median edge length.
  double near_data_mm = 0.0;
  // Pieces are tested again against the textures of the map's materials
  // (server/map/piece_resplit.h): a piece whose series shows a change between
  // two of them that its drag's own test missed is split there, and its pieces
  // are grouped into regions again with the parts. A material's texture is fitted
  // only from at least min_texture_rows pairs.
  bool split_against_materials = true;
  KnownTextureSplitOptions known_split;
  int min_texture_rows = 300;
  // Each region is tested against the textures of the materials (fitted
  // from min_texture_rows pairs or more) and moves to the one that explains
  // its pairs best, beyond chance at known_split's false-alarm probability
  // (server/map/texture_assignment.h): the merge rule's tests accept a short
  // noisy piece as alike to several materials.
  bool assign_by_texture = true;
  // Regions alike by the merge rule, wherever they lie, are one material:
  // each reports the estimates (mu, its se, roughness) of all the
  // material's pieces. Their extents are unchanged.
  bool pool_alike_regions = true;
  // Boundaries are linked between materials, not regions
  // (boundary_links.h): one material met in several places is several
  // regions (a band cut into stretches by pieces that straddle its
  // neighbour), and crossings into two stretches of one band are crossings
  // of one boundary; a stretch of the same material in a link's corridor
  // does not contradict it. A link's points take the region of their
  // material whose data lies nearest.
  bool link_materials = true;
  // A material's mu (and its se and spread) is pooled from its pieces long
  // enough for their own roughness fit (FitOptions::min_roughness_piece_mm)
  // when it has at least this many; from all its pieces otherwise; 0 = always
  // from all. A short piece is the one a change's location error and a
  // slowly wandering texture bias most, and the precision weights do not
  // see it: on dotted_egg (seed 4 through the service) four 1-3 mm pieces
  // at the masonite dot's rim, read 0.23-0.29 and alike to it only for their
  // large se, joined its material and took it from 0.340 to 0.331, past the
  // midpoint to rubber: the whole dot mapped rubber.
  int min_fitted_pieces_for_mu = 3;
  // "Long enough" above: a piece's extent of at least this many mm; 0 = its
  // own roughness fit (5 mm less a guard at each change, the build before).
  // A drag across a 6 mm strip leaves 4-5 mm pieces, too short to fit but
  // not biased (over twelve scan jobs, strip pieces of 4-6 mm read 0.354-0.367
  // for masonite's 0.36; under 4 mm, rim slivers, 0.14-0.26); leaving them
  // out pooled a strip's mu from three crossings (docs/method.md).
  double min_mu_piece_mm = 4.0;
  // A piece whose pair series another material's texture explains better
  // than its own material's, beyond chance at known_split's false-alarm
  // probability (the test texture_assignment.h makes of a region, made of
  // each piece), is left out of its material's mu. A region's pieces are
  // alike pairwise by the merge rule, whose tests accept short noisy pieces
  // as alike to anything, so a region can hold a precise piece of another
  // material beside them, and precision weights let it take over the mean:
  // on held_block (500 Hz, seed 3) a 6 mm wood piece (0.416, se 0.015,
  // spread 0.03) sat in a region with four short masonite pieces, joined
  // masonite and carried 44 % of its weight, taking the masonite strip to
  // 0.394 (truth 0.36, its own region's pieces 0.369), mapped as wood
  // everywhere. Leaving a piece out costs only its precision. Off: every
  // piece counts (the build before).
  bool exclude_misfit_pieces_from_mu = true;
  // A misfit piece (above) whose region has pieces that fit it is moved out
  // of that region into one of its own, of the material whose texture
  // explains its series best: the map then draws that material where the
  // piece lies instead of the region's. The merge rule's pairwise tests let
  // a region gather pieces of two materials of low contrast: on held_block
  // (100 Hz, seed 2) one region held rubber pieces (0.300, 0.302) beside
  // masonite ones (0.33-0.34), and the rubber strip mapped as masonite
  // where they lay. Left out of the material's mu, the rubber pieces were
  // still drawn with it. A moved piece, like any misfit, counts in no
  // material's mu (with exclude_misfit_pieces_from_mu): its
  // series fit the material it moved to better, not necessarily well (a
  // piece that straddles a missed change is explained best by one side's
  // texture and reads between the two), so the materials' estimates are
  // those the exclusion above gives, and only where they are drawn changes.
  // Off: a misfit stays in its region (the build before).
  bool move_misfit_pieces = true;
  // A misfit moves only to a material its statistics are alike to by the
  // merge rule (TexturesAlike against the material's pooled pieces), as a
  // region moves only among such materials (texture_assignment.h); one
  // that is not stays in its region, still left out of the mu. The
  // conditional likelihood of a slow texture barely sees its mean: under
  // masonite's (a1 + a2 = 0.88) a series 0.076 above masonite's mu costs
  // innovations of 0.12 x 0.076 = 0.009 against their sd of 0.16, so a wood
  // piece (0.431) with a transitional pair or two, far less likely under
  // wood's narrow innovations, moved to masonite (0.355 +- 0.009). On
  // held_block (seed 7, in-process) it lay 0.8 mm outside the 9 mm
  // sandpaper dot's edge, a third material that contradicted the dot's
  // circle (boundary_dots.h), and the dot was drawn from its crossings
  // alone: 83.5 % right, 91.0 % with this rule. Off: a misfit moves to the
  // material of the best texture whatever its mu (the build before).
  bool move_only_to_alike_material = true;
  // A material that the other materials explain better than its own
  // texture does, its free choices paid (a mixture of pieces that straddle
  // the boundary between two of them, mixture_materials.h), is dissolved:
  // each of its regions moves to the material whose texture explains its
  // pieces best, and its pieces take no part in fitting the textures the
  // split against the materials tests with, so that it cuts them where
  // they cross. Off: every material found stays (the build before).
  bool dissolve_mixture_materials = true;
  // A change is no crossing of a boundary when the piece on one side of it
  // is the drag's last (or first), shorter than this, and its mu within
  // end_piece_mark_z combined standard errors of the other side's: such a
  // piece has too few pairs to say which material it is, and the map's
  // assignment of it draws a crossing where none was shown. Over the stored
  // friction jobs of 15 scenes x 6 seeds, 56 % of the 457 such changes lay
  // more than 1 mm from any true boundary, against 12 % of the 900 at end
  // pieces that were told apart (z >= 2). Measured on the stone (seed 1): a
  // 1 mm end piece of its masonite strip read 0.241 next to 0.408 (se 0.10,
  // 0.06), was put in wood, and its change drew the strip's edge 3 mm inside
  // the strip. The piece's data stay in the map; only the crossing goes.
  // 0 = every change a crossing (the build before).
  double min_end_piece_mark_mm = 1.5;
  double end_piece_mark_z = 2.0;
  // Nor does such a piece refuse a boundary: the corridors of the links,
  // lines, corners, bridges and dots (boundary_links.h) are checked against
  // the other pieces' data. dotted_egg (seed 1, in-process): a drag's last
  // 1.2 mm read 0.137 next to glass's 0.106, was put with the masonite, lay
  // 0.6 mm outside the masonite dot's circle and refused it; the dot was
  // 80.5 % right, 94.5 % without the veto. Off: every piece's data check the
  // corridors (the build before; the plan's map, so plans are unchanged).
  bool boundaries_ignore_unconfirmed_end_pieces = true;
  // A piece between two changes of its drag, shorter than
  // min_end_piece_mark_mm, of a third material, whose mu lies between its
  // neighbours' (to end_piece_mark_z of its se), is a transition: the
  // detector put two changes round one step, and the piece between them
  // reads a blend of the two sides. Its drag crossed one boundary, from the
  // one neighbour's material to the other's, in its middle: that is the
  // crossing marked, and the piece's data refuse no boundary (they stay in
  // the map). dotted_egg (seed 1, in-process): four drags crossed the rubber
  // dot's or a sandpaper dot's edge with such a piece (1.3-1.4 mm, reading
  // 0.14-0.31 between glass's 0.106 and the dot's), each put with the
  // masonite; they marked glass/masonite and masonite/dot crossings instead
  // of the dot's, and their data refused the dots' circles: the rubber dot
  // 94.5 % right, 99.25 % with this rule. Off: a crossing at every change
  // between materials (the build before; the plan's map, so plans are
  // unchanged).
  bool transition_pieces_mark_one_crossing = true;
  // A transition is shorter than this. The detector's two changes round one
  // step fall up to ~2 mm apart where the piece between them has few pairs:
  // the bottle (seed 4, in-process) had a drag cross its patch's side with a
  // 1.8 mm piece reading 0.16 +- 0.10 between glass's 0.13 and sandpaper's
  // 0.48, put in a material of its own; its two crossings linked to nothing,
  // no link was drawn along the side past its data, and the patch's corner
  // was cut off (94.75 % right; 99.25 % with 2.5 mm). A strip of a third
  // material narrower than this is below what the map draws anyway (the
  // scenes' narrowest is 6 mm), and a piece reading outside its neighbours'
  // mu is never a transition. Over 160 in-process jobs (20 scenes x seeds
  // 1-8, docs/method.md "A transition up to 2.5 mm long"): share right
  // +0.0123 +- 0.0025 points, goals met 153 -> 154. 1.5 (the end pieces'
  // min_end_piece_mark_mm, which it shared): the build before.
  double max_transition_piece_mm = 2.5;
  // Floors on a piece's mu_se and spread: synthetic or noise-free data can
  // report 0, which the merge statistics divide by.
  double min_mu_se = 1e-4;
  double min_spread = 1e-4;
  bool IsValid(std::string* why) const;
};

struct TextureRegion {
  // Pooled over its material's pieces (RegionMapOptions::pool_alike_regions;
  // without it, over its own).
  PieceStatistics statistics;
  PieceStatistics own_statistics;  // pooled over its own pieces
  int material = -1;               // regions of one material share their estimates
  std::vector<int> pieces;        // indices into the pieces given
  // The material's pieces behind statistics.mu (indices as `pieces`): its
  // pieces of min_mu_piece_mm or longer when there are
  // min_fitted_pieces_for_mu of them, all of them otherwise. Shared by the
  // material's regions.
  std::vector<int> mu_pieces;
  int roughness_pieces = 0;       // pieces with their own roughness fit (of the material)
  std::vector<double> reflection;  // medians (empty without roughness; of the material)
  double sigma = 0.0;             // median (0 without roughness)
  bool has_roughness() const { return roughness_pieces > 0; }
};

class RegionMap {
 public:
  // `level` (e.g. the finest level of the surface, refined until its edges
  // are ~1-2 mm) must outlive the map. Errors (INVALID_ARGUMENT): invalid
  // options, an empty level, sizes of positions / neighbours / triangles
  // that disagree.
  static absl::StatusOr<RegionMap> Create(const SurfaceLevel& level, const RegionMapOptions& options = {});

  // Replaces the pieces and rebuilds the map. Errors (INVALID_ARGUMENT, naming
  // the piece): no pieces, a piece without points, non-finite points or
  // invalid texture (LineSample rules). On error the map keeps its state.
  // Pieces identical to those at the same index in the previous call keep
  // their projection onto the level (a plan adds pieces at the end).
  // pieces() are those the map is built from: the given ones, or their parts
  // where they were split against the map's materials.
  absl::Status SetPieces(std::vector<MapPiece> pieces);

  // Points about to be measured (issued drags' sites): they lower the
  // far-from-data uncertainty near them, not the values. Errors: non-finite
  // points. Allowed before any piece is set.
  absl::Status SetPendingPoints(std::vector<Eigen::Vector3d> points);

  bool has_pieces() const { return !pieces_.empty(); }
  int vertex_count() const { return static_cast<int>(level_->limit_positions.size()); }
  const SurfaceLevel& level() const { return *level_; }
  const std::vector<MapPiece>& pieces() const { return pieces_; }
  const std::vector<TextureRegion>& regions() const { return regions_; }
  const std::vector<int>& piece_region() const { return piece_region_; }
  // Per piece of pieces(), as the merge rule and the estimates weigh it:
  // its mu_se is the fit's widened, next to a change, by the share of the
  // neighbour's mu that may lie inside it (change_location_mm).
  const std::vector<PieceStatistics>& piece_statistics() const { return piece_statistics_; }

  // Per vertex of the level (empty before the first SetPieces).
  const std::vector<int>& region() const { return region_; }            // -1: no data reachable
  const std::vector<int>& second_region() const { return second_region_; }  // -1: none
  const std::vector<double>& mu() const { return mu_; }
  const std::vector<double>& mu_std() const { return mu_std_; }
  const std::vector<double>& data_distance_mm() const { return data_distance_mm_; }  // incl. pending points
  const std::vector<double>& boundary_probability() const { return boundary_probability_; }  // p above
  // The two position-dependent terms of var(v) above: p (1 - p) (mu_2 - mu_r)^2
  // and s^2 (1 - exp(-2 d / l)); what one more drag near v could remove.
  const std::vector<double>& boundary_variance() const { return boundary_variance_; }
  const std::vector<double>& far_variance() const { return far_variance_; }
  // What serving region b's estimates where region a lies costs, in mu^2:
  // (metric.mu_scale * TextureDistance(a, b, metric))^2. (mu_b - mu_a)^2
  // when metric.property is kFriction, and for any property where either
  // region has no roughness (one too smooth or too short to fit cannot be
  // told apart by it). 0 for an unknown region.
  double ConfusionCost(int a, int b, const TextureDistanceOptions& metric) const;
  // What the surface far from any data may differ by, in the same units:
  // prior_mu_std()^2 for the friction term, plus, for the roughness terms,
  // mu_scale^2 times the variance over the pieces with roughness of their
  // scaled reflection coefficients and log sigma. A kRoughness metric with
  // fewer than two such pieces falls back to prior_mu_std()^2.
  double PriorTextureVariance(const TextureDistanceOptions& metric) const;
  // reflection()[j][v] is k_(j+1) at v; NaN where v's region has no roughness.
  const std::vector<std::vector<double>>& reflection() const { return reflection_; }
  const std::vector<double>& log_sigma() const { return log_sigma_; }  // NaN where no roughness
  int roughness_order() const { return static_cast<int>(reflection_.size()); }
  int boundary_links() const { return links_; }      // links drawn between crossings
  int boundary_corners() const { return corners_; }  // corners drawn between chain ends
  int boundary_bridges() const { return bridges_; }  // boundaries carried across a change beyond them
  int boundary_dots() const { return dots_; }        // circles drawn round dots (boundary_dots.h)
  int boundary_rectangles() const { return rectangles_; }  // small patches' rectangles (boundary_rectangles.h)
  int regions_moved_by_texture() const { return regions_moved_by_texture_; }  // assign_by_texture
  int pieces_moved_by_texture() const { return pieces_moved_by_texture_; }    // move_misfit_pieces
  // Materials dissolved (dissolve_mixture_materials), over both groupings
  // when the pieces were split against the materials.
  int materials_dissolved() const { return materials_dissolved_; }
  // Pieces given that were split against the map's materials
  // (RegionMapOptions::split_against_materials); pieces() holds their parts.
  int split_pieces() const { return split_pieces_; }
  // Where drags crossed from one region into another (a change inside a
  // drag between pieces of different regions), in piece order.
  const std::vector<ChangeMark>& change_marks() const { return marks_; }
  double prior_mu_std() const { return prior_mu_std_; }
  // The friction variance of a point d mm from the nearest data, beside its
  // region's own: prior_mu_std()^2 (1 - exp(-2 d / correlation_length_mm())).
  double FarVariance(double d) const;
  double correlation_length_mm() const { return correlation_length_mm_; }

  // Values at vertex v (0 <= v < vertex_count(), after SetPieces).
  MapValue VertexValue(int v) const;
  // At a point of the level's triangle point.triangle (barycentric): the
  // region whose interpolated distance is least. Errors: no pieces yet
  // (FAILED_PRECONDITION), a triangle out of range or non-finite barycentrics
  // (INVALID_ARGUMENT).
  absl::StatusOr<MapValue> ValueAt(const SurfacePoint& point) const;
  // At any point: projected onto the level first.
  absl::StatusOr<MapValue> ValueAtPosition(const Eigen::Vector3d& position) const;
  // The values at every vertex of another level of the same surface (its
  // limit positions projected onto this one). A coarser level's vertices are
  // a prefix of this level's (the numbering contract) and read directly.
  absl::StatusOr<std::vector<MapValue>> ValuesAtLevel(const SurfaceLevel& other) const;

  // The unit tangent direction at v across the nearest boundary, towards
  // v's second region: the gradient of (P_2 - P_r) over v's neighbours in
  // the tangent plane. Zero when v has no second region.
  Eigen::Vector3d CrossingDirection(int v) const;
  // The data point (on a piece) nearest to v; v's own position when no data
  // is reachable.
  Eigen::Vector3d NearestDataPoint(int v) const;

 private:
  RegionMap() = default;
  struct PlacedPiece {
    std::vector<Eigen::Vector3d> points;   // as given (to recognise it next time)
    std::vector<LabelledSeed> seeds;       // label = piece index
    std::vector<SurfaceSeed> surface_seeds;  // label = piece index
    std::vector<Eigen::Vector3d> data_points;  // the resampled points on the surface
  };
  absl::Status Validate(const std::vector<MapPiece>& pieces) const;
  PlacedPiece Place(const MapPiece& piece, int index) const;
  // Building the map from pieces_: grouping them into regions and materials
  // (merge rule, estimates), then spreading the regions over the surface
  // (diagram, random walker, links, corners, values). A split against the
  // materials groups twice and spreads once.
  // Errors: a broken invariant (the pieces were validated by SetPieces).
  absl::Status GroupPieces();
  absl::Status SpreadRegions();
  // `out`'s estimates (statistics, roughness) from pieces `piece_indices`;
  // misfits, moved or not (better_material[i] >= 0), are left out of its mu
  // (exclude_misfit_pieces_from_mu), and so are the pieces of dissolved
  // materials; either only when any other is left.
  void Summarise(const std::vector<int>& piece_indices, const std::vector<PieceStatistics>& statistics, int order,
                 const std::vector<int>& better_material, TextureRegion* out) const;
  // Per piece: the material whose texture explains its pair series best,
  // where that beats its own material's beyond chance; -1 where none does
  // (its own fits), and everywhere when neither misfit option is on or fewer
  // than two materials have a texture. `textures`: the materials' textures
  // (MaterialTextures of `piece_material`) when already fitted; empty = fit
  // them here.
  std::vector<int> MisfitPieces(const std::vector<int>& piece_material,
                                std::vector<std::optional<SeriesTexture>> textures) const;
  // Moves each misfit piece (better_material[i] >= 0) whose region keeps a
  // piece that fits into a region of its own of that material, appended to
  // regions_ (move_misfit_pieces); updates piece_region_, `region_material`,
  // `own` and `piece_material` (better_material keeps marking the moved
  // pieces, left out of every mu). Returns how many moved.
  int MoveMisfitPieces(const std::vector<PieceStatistics>& statistics, std::vector<int>* better_material,
                       std::vector<int>* region_material, std::vector<PieceStatistics>* own,
                       std::vector<int>* piece_material);
  // Dissolves the materials that the others explain (dissolve_mixture_
  // materials): their regions move to the material whose texture explains
  // their pieces best; `region_material` is renumbered 0.. and `textures`
  // (the materials' textures, MaterialTextures of `piece_material`) and
  // `piece_material` follow. Returns how many were dissolved; errors as
  // MixtureMaterials'.
  absl::StatusOr<int> DissolveMixtureMaterials(std::vector<int>* region_material,
                                               std::vector<std::optional<SeriesTexture>>* textures,
                                               std::vector<int>* piece_material);
  // Each region's material (0..), given each region's own pool: alike
  // regions grouped, or each its own without pool_alike_regions.
  std::vector<int> Materials(const std::vector<PieceStatistics>& own) const;
  // `material` with regions moved to the material whose texture fits them
  // best (assign_by_texture, texture_assignment.h), renumbered 0...
  // `fitted` gets the textures of the materials as given.
  std::vector<int> AssignByTexture(const std::vector<PieceStatistics>& own, std::vector<int> material,
                                   std::vector<std::optional<SeriesTexture>>* fitted);
  void RecomputeUncertainty();
  double PointVariance(int region, int second, double p, double d) const;
  double BoundaryVariance(int region, int second, double p) const;
  // Whether `end`, a piece beside a change to `other` on its drag, is too
  // short and too alike to `other` to confirm the change as a crossing
  // (RegionMapOptions::min_end_piece_mark_mm).
  bool UnconfirmedEndPiece(const MapPiece& end, const MapPiece& other) const;
  // Whether pieces_[piece] is unconfirmed next to either neighbour on its drag.
  bool UnconfirmedEndPiece(int piece) const;
  // Whether pieces_[piece] is a transition between its neighbours on its
  // drag (RegionMapOptions::transition_pieces_mark_one_crossing); side[i]:
  // piece i's material (or region, without link_materials).
  bool TransitionPiece(int piece, const std::vector<int>& side) const;

  const SurfaceLevel* level_ = nullptr;
  RegionMapOptions options_;
  std::shared_ptr<const MeshLocator> locator_;
  std::shared_ptr<LabelPropagation> propagation_;
  std::vector<std::vector<double>> probability_;  // [region][vertex]
  int links_ = 0;
  int corners_ = 0;
  int bridges_ = 0;
  int dots_ = 0;
  int rectangles_ = 0;
  int regions_moved_by_texture_ = 0;
  int pieces_moved_by_texture_ = 0;
  int materials_dissolved_ = 0;
  // Per piece of pieces_: whether it was a piece of a dissolved material
  // (left out of the textures the split against the materials tests with).
  std::vector<bool> of_dissolved_material_;
  std::vector<ChangeMark> marks_;
  // Data points (pieces' and links') by cell of near_data_mm, for the
  // near-data rule; empty when the rule is off.
  double near_data_mm_ = 0.0;
  LabelledPointGrid near_data_;
  int NearestDataRegion(const Eigen::Vector3d& p) const;
  double correlation_length_mm_ = 0.0;

  // The pieces as given (and their placement, kept so that the next call
  // places only new pieces), and those the map is built from: the given
  // ones, split where a known texture test found a change.
  std::vector<PlacedPiece> given_placed_;
  int split_pieces_ = 0;
  std::vector<PlacedPiece> parts_placed_;  // only when split_pieces_ > 0
  std::vector<MapPiece> pieces_;
  // The placements of pieces_ (no copy of the given ones when none was split).
  const std::vector<PlacedPiece>& placed() const { return split_pieces_ > 0 ? parts_placed_ : given_placed_; }
  std::vector<Eigen::Vector3d> pending_;
  std::vector<TextureRegion> regions_;
  std::vector<int> piece_region_;
  std::vector<PieceStatistics> piece_statistics_;
  NearestLabels nearest_;  // labelled by region
  std::vector<Eigen::Vector3d> seed_points_;  // of nearest_'s seeds
  double prior_mu_std_ = 0.0;
  std::vector<int> region_, second_region_;
  std::vector<double> mu_, mu_std_, data_distance_mm_, boundary_probability_, log_sigma_;
  std::vector<double> boundary_variance_, far_variance_;
  std::vector<std::vector<double>> reflection_;
};

}  // namespace surfmap
