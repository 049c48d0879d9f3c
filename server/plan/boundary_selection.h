// Where the boundary-seeking plan sends the next drag, and which way
// (PlanMode::kBoundary). A drag measures the surface along its path, and
// where it crosses a boundary it fixes a point of it; the map joins
// neighbouring crossings (boundary_links.h, up to a drag length apart), so
// one crossing settles the boundary about half a drag length either way
// along it. So a drag centred at c along the unit direction u, with data
// window c - h u .. c + h u (the middle 80 % of the drag), removes
//
//   gain(c, u) = sum over v within `corridor` of the window's segment of
//                  area(v) * (far_variance(d(v)) - far_variance(min(d(v), t(v))))
//              + sum over v within h of c of
//                  area(v) * p(v) (1 - p(v)) * cost(v) * |u . n(v)|
//
// (region_map.h; mu^2 mm^2, the squared error mass the drag can remove),
// d(v) the distance from v to the nearest data and t(v) to the drag's path:
// the drag brings v's data nearer only where its path passes nearer than
// the data it has (with far_gain_expected; without it, the build before,
// the whole far_variance(d(v)) of the corridor counts),
// p(v) the boundary probability and cost(v) what confusing the two regions
// there costs: their mu jump squared for a friction job; for a roughness
// or both job their texture distance in mu^2 (RegionMap::ConfusionCost), with
// far_variance scaled to the pieces' spread in that metric, so a boundary
// between alike frictions of different roughness is not starved;
// n(v) the direction across the boundary at v (RegionMap::CrossingDirection):
// a drag across a boundary pins it, one along it settles only the strip it
// runs on. corridor = a quarter of the drag length: beyond that on either
// side of its path the map is interpolated from other drags. Near a boundary
// no drag has pinned, the band where the map may be wrong is as wide as the
// gap between the data on either side, so the gain prefers unpinned
// stretches of boundary; far from data it prefers the middle of the gap.
// Vertices within reach (half the drag length) of a drag already issued count
// as covered, so several rigs get different places.
//
// The search: every candidate's sum over the disc of radius h (cheap, any
// direction), then for the best kShortlist of them every direction in
// 180 / kDirections degree steps.
//
// Squared error is what the map's mu RMSE counts; a point the map gives the
// wrong material is also simply wrong, whatever the two mu are, and the
// squared jump alone starves a boundary of low contrast. On the held-out
// stone (seed 8) a 7 mm masonite strip on wood (0.06 apart) weighed 27 times
// less than a glass patch (0.31 apart) and took 5 of the 178 chosen drags,
// the glass 41. With misclassification_cost c > 0 a point at a boundary
// between two materials also costs c (mu^2) times the chance it is given
// the wrong one:
//
//   boundary cost(v) = jump^2 + c.
//
// The far-from-data term grows by the factor the boundaries' total grew by,
// so the drags that explore keep their share (grown by c / prior variance
// instead, as "wrong material" would have it, it took a big block's strip
// drags for wood: 76 of 178 chosen drags explored plain wood, 41 before)
// and c only re-shares the boundaries' drags among them. c = 0 is the
// squared error alone (the build before).
#pragma once

#include <span>
#include <vector>

#include <Eigen/Core>
#include "server/map/region_map.h"

namespace surfmap {

// What one more drag on a material is worth while its mu is known too
// roughly to tell it from another material's: its area times c times the
// fall in the chance that its truth lies past the midpoint to the nearest
// other material's mu (its truth taken as normal about the estimate, to
// mu_se),
//
//   area * c * (erfc(gap / (2 sqrt(2) se)) - erfc(gap / (2 sqrt(2) se')))
//   se' = se sqrt(piece_mm / (piece_mm + length_mm))
//
// with piece_mm the length of the pieces behind its mu and length_mm what
// the drag adds (precision grows with length). A material whose mu is
// settled (se far below the gap) or that no mu tells apart from another
// (gap 0: texture does) gains nothing. Measured: on the held-out pebble a
// 6 mm masonite strip (mu 0.36) read 0.325 +- 0.017 from 7 drag-sized
// pieces, nearer rubber's 0.305, and the whole strip was scored rubber (0 %
// classified right, seed 14 in-process); the squared-error terms value
// settling it at ~1 % of a boundary's gain.
double MaterialMuRiskGain(double area_mm2, double mu_se, double gap, double piece_mm, double length_mm,
                          double misclassification_cost);

// The weight of c at a boundary whose smaller side's material covers
// `smaller_area` of the map, the materials `mean_area` on average: their
// ratio, clamped to [1, max_weight] (SamplingPlanOptions::
// small_material_weight_max says why). A material of no area yet: the most.
double SmallMaterialWeight(double smaller_area, double mean_area, double max_weight);

struct BoundarySelection {
  int vertex = -1;           // of the map's level; -1 when no candidate has any gain
  double gain = 0.0;         // mu^2 mm^2, over the corridor
  double boundary_share = 0.0;  // of the gain
  Eigen::Vector3d direction = Eigen::Vector3d::Zero();  // unit tangent
  int directed = -1;         // Select: the directed candidate chosen, -1 when none
};

// A drag proposed with its direction fixed and a gain of its own on top of
// the map's (e.g. following a boundary, boundary_tracing.h).
struct DirectedCandidate {
  int vertex = -1;
  Eigen::Vector3d direction = Eigen::Vector3d::Zero();  // unit tangent
  double extra_gain = 0.0;                              // mu^2 mm^2
};

class BoundarySelector {
 public:
  // `level` is the map's level (the selector keeps its vertex areas and a
  // spatial grid of its vertices); `drag_length_mm` the probe's segment.
  // `metric`: what the errors are measured in (RegionMap::ConfusionCost and
  // PriorTextureVariance): with property kFriction, mu^2 (the mu jump);
  // otherwise the texture distance over that property, in mu^2.
  // `misclassification_cost`: c above (mu^2; 0 = squared error alone).
  // `material_mu_risk`: whether a drag also gains by settling a material's
  // mu (MaterialMuRiskGain below). `small_material_weight_max`: c is
  // weighed by SmallMaterialWeight at each boundary (1 = not at all).
  // `far_gain_expected`: the far-from-data term at a vertex is what bringing
  // its distance to data down to the drag's path takes off its far variance
  // (FarShareRemoved), not all of it.
  BoundarySelector(const SurfaceLevel& level, double drag_length_mm, const TextureDistanceOptions& metric = Friction(),
                   double misclassification_cost = 0.0, bool material_mu_risk = false,
                   double small_material_weight_max = 1.0, bool far_gain_expected = false);

  // The friction-only metric: boundaries weighed by their mu jump.
  static TextureDistanceOptions Friction() {
    TextureDistanceOptions metric;
    metric.property = TextureProperty::kFriction;
    return metric;
  }

  // The candidate and direction with the largest gain among vertices with
  // candidate[v] != 0 (one entry per vertex of the level; vertices beyond its
  // size are not candidates). Ties go to the lower vertex and the first
  // direction. `covered` are the centres of drags issued and not yet measured.
  // `directed` drags compete too, each with the map's gain along its own
  // direction plus its extra gain (they need not be candidates); the result's
  // `directed` says which one won (-1: none).
  BoundarySelection Select(const RegionMap& map, std::span<const char> candidate,
                           const std::vector<Eigen::Vector3d>& covered,
                           std::span<const DirectedCandidate> directed = {}) const;

  // The best direction for a drag at v (e.g. a coverage site issued after
  // some data came in) with its gain and boundary share.
  BoundarySelection BestDirection(const RegionMap& map, int v, const std::vector<Eigen::Vector3d>& covered) const;

  // BestDirection's answer (`best`), and the best of `among` (unit tangents
  // at v) by the same gain (`among`; ties go to the first), from one pass
  // over the map. Either is empty (vertex -1) when no direction gains
  // anything, the map has no pieces or v is not a vertex of the level.
  struct DirectionChoice {
    BoundarySelection best;
    BoundarySelection among;
  };
  DirectionChoice BestDirectionAndAmong(const RegionMap& map, int v, std::span<const Eigen::Vector3d> among,
                                        const std::vector<Eigen::Vector3d>& covered) const;

  // The gain below which a drag is not worth making: a resolution-sized
  // error (mu_resolution) over the whole corridor.
  double MinGain(double mu_resolution) const;

  double reach_mm() const { return 0.5 * drag_length_mm_; }
  double half_window_mm() const { return half_window_mm_; }  // h above

  // The vertex of the level nearest p within radius_mm (ties: the lower);
  // -1 when none is.
  int NearestVertex(const Eigen::Vector3d& p, double radius_mm) const;

 private:
  template <typename Fn>
  void ForEachWithin(const Eigen::Vector3d& centre, double radius, const Fn& fn) const;
  // A material whose mu is known too roughly to tell it from another's.
  struct MaterialRisk {
    double area = 0.0;      // mm^2, of the vertices the map gives it
    double mu_se = 0.0;     // of its pooled mu
    double gap = 0.0;       // |mu - mu'| to the nearest other material's
    double piece_mm = 0.0;  // the length of the pieces behind its mu
  };
  struct Removable {
    std::vector<double> far;       // area * far variance
    std::vector<double> data_mm;   // far_gain_expected: distance to the nearest data (0 where covered)
    const RegionMap* map = nullptr;  // far_gain_expected: whose FarVariance the far term is
    std::vector<double> boundary;  // area * boundary variance
    std::vector<Eigen::Vector3d> across;  // n(v), zero where no boundary
    std::vector<int> material;     // per vertex, of its region; -1 none or covered
    std::vector<MaterialRisk> materials;
    std::vector<double> material_density;  // per vertex: a whole drag's material gain per mm^2 of its disc
  };
  Removable RemovableVariance(const RegionMap& map, const std::vector<Eigen::Vector3d>& covered) const;
  // The best of `directions` for a drag at v over `near` (empty when none
  // gains anything; ties go to the first).
  BoundarySelection BestOf(int v, std::span<const Eigen::Vector3d> directions, const std::vector<int>& near,
                           const Removable& removable) const;
  // The vertices within the window's reach of v, the corridor included.
  std::vector<int> Near(int v) const;
  // What a drag at v along u (unit tangent) gains, over `near` (the
  // vertices within the window's reach of v), in one pass: far from data,
  // at boundaries, and by settling the materials' mu (MaterialMuRiskGain of
  // the window's length in each material).
  struct Gains {
    double far = 0.0, boundary = 0.0, material = 0.0;
    double total() const { return far + boundary + material; }
  };
  Gains GainAlong(int v, const Eigen::Vector3d& u, const std::vector<int>& near, const Removable& removable) const;
  // Of vertex w's far variance, the share a drag whose path passes path_mm
  // from it removes: all of it without far_gain_expected; with it, what
  // bringing its distance to data down to path_mm takes off.
  static double FarShareRemoved(const Removable& removable, int w, double path_mm);
  // The materials' risks (material_mu_risk; nothing without it or c).
  void AddMaterialRisks(const RegionMap& map, Removable* r) const;
  // Each material's area on the map (its regions' vertices'), indexed by
  // material, 0 for a material without vertices.
  std::vector<double> MaterialAreas(const RegionMap& map) const;
  double Gain(const MaterialRisk& m, double length_mm) const {
    return MaterialMuRiskGain(m.area, m.mu_se, m.gap, m.piece_mm, length_mm, misclassification_cost_);
  }

  const SurfaceLevel* level_;
  double drag_length_mm_;
  TextureDistanceOptions metric_;
  double misclassification_cost_;
  bool material_mu_risk_;
  double small_material_weight_max_;
  bool far_gain_expected_;
  double half_window_mm_;  // h
  double corridor_mm_;
  std::vector<double> area_;  // a third of the area of the triangles around each vertex
  Eigen::Vector3d lo_;
  Eigen::Vector3i dims_;
  double cell_mm_;
  std::vector<std::vector<int>> grid_;
};

}  // namespace surfmap
