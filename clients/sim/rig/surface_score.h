// How good is a friction/roughness map of a scene, judged on the true surface
// (not on the map's own vertices): seeded random points spread by area over
// a dense level of the scene's Loop surface, each with its true material
// (Scene::MaterialIndexAt), and the map read there. Shared by surfmap-mapsim
// (the map in process) and `surfmap-rig score` (a map file from the server).
//
// Definitions:
// - classified right: the scene material whose mu is nearest the map's mu at
//   the point (ties to the lower index) is the point's true material.
// - mu RMSE: over the points, map mu against the true material's mu.
// - boundary localisation: on every edge of the dense level whose ends have
//   different true materials, the true boundary point is found by bisection
//   of the straight edge (to edge length / 2^bisections); the same for the
//   map's classification on edges whose ends the map classifies differently.
//   boundary_error_mm: mean distance from each map boundary point to the
//   nearest true one (how far off the map puts the boundaries it draws, and
//   boundaries it invents); missed_boundary_mm: mean distance from each true
//   boundary point to the nearest map boundary point (true boundaries the map
//   misses or displaces). misclassified_distance_mm: mean distance from the
//   misclassified random points to the nearest true boundary point.
// - roughness per rough region: medians over the region's random points at
//   which the map has a roughness model of a1, a2 and sigma, against the
//   region's material. A material is rough when its texture's process
//   standard deviation (ArProcessVariance) is at least rough_min_process_std_n.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json.hpp>
#include "absl/status/statusor.h"
#include "clients/sim/rig/scene.h"

namespace surfmap {

// What a map says at a point of the surface.
struct MapReading {
  double mu = 0.0;
  bool has_roughness = false;
  double a1 = 0.0, a2 = 0.0, sigma = 0.0;
};
// Reads a map at a point (mm) on or near the surface.
using MapReader = std::function<absl::StatusOr<MapReading>(const Eigen::Vector3d& point)>;

struct SurfaceScoreOptions {
  int points = 5000;         // random points on the true surface
  std::uint64_t seed = 1;    // which points
  // A region's share classified right is measured on at least this many of
  // its points: a region that drew fewer of the `points` (a 16 mm patch on
  // a vase draws ~14 of 5,000, so each point moves its share by 7 %, and its
  // standard error at 85 % is 9.5 %) gets more, drawn the same way (area-
  // uniform over the surface, kept when inside it), up to
  // max_region_draws_per_point * points draws in all. 400 points put the
  // standard error at 85 % below 1.8 %. The extra points count only for
  // their region's row; the overall share, the mu RMSE and the misclassified
  // points use the `points` alone. 0: no extra points.
  int min_region_points = 400;
  int max_region_draws_per_point = 100;
  // Loop level of the scene's surface the points and boundaries are taken on
  // (the "true dense surface"): level 4 has edges of ~1-2 mm on the built-in
  // scenes, and the bisection below resolves boundaries to ~0.03 mm. A mesh
  // too dense for it (a scan) is taken at the finest level within
  // kMaxFinestTriangles (loop_surface.h).
  int truth_level = 4;
  int boundary_bisections = 6;
  // 3x the simulated rig's force noise (0.015 N): a texture below this is not
  // resolvable, so its region is not scored for roughness.
  double rough_min_process_std_n = 0.05;
  bool IsValid(std::string* why) const;
};

struct RegionScore {
  std::string name;       // "rubber (regions[0])", "glass (default)"
  std::string material;
  double truth_mu = 0.0;
  int points = 0;         // random points in the region (the first region containing them), extra ones included
  int extra_points = 0;   // of them, drawn for the region alone (SurfaceScoreOptions::min_region_points)
  double classified_right = 0.0;  // share of its points (NaN without points)
  double map_mu_mean = 0.0;
  double map_mu_rmse = 0.0;
  bool rough = false;
  double truth_a1 = 0.0, truth_a2 = 0.0, truth_sigma = 0.0;
  int points_with_roughness = 0;
  double a1_median = 0.0, a2_median = 0.0, sigma_median = 0.0;  // NaN without roughness
};

// A scored point the map classifies wrong.
struct MisclassifiedPoint {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  int truth_material = -1;
  int region = -1;           // the scene region it lies in; -1: the default material
  bool region_only = false;  // drawn for its region's row alone, not one of the random points
  double map_mu = 0.0;
  double boundary_distance_mm = 0.0;  // to the nearest true boundary point
};

struct SurfaceScore {
  int points = 0;
  double classified_right = 0.0;
  double mu_rmse = 0.0;
  double mu_max_abs_error = 0.0;
  int truth_boundary_points = 0;
  int map_boundary_points = 0;
  double boundary_error_mm = 0.0;         // NaN when either set of boundary points is empty
  double boundary_error_p90_mm = 0.0;
  double missed_boundary_mm = 0.0;
  double misclassified_distance_mm = 0.0;  // NaN when nothing is misclassified
  std::vector<RegionScore> regions;       // scene regions in file order, then the default material
  // Every scored point classified wrong, the random ones first; the
  // region_only ones say where a small region's row lost its share.
  std::vector<MisclassifiedPoint> misclassified;
};

class SurfaceScorer {
 public:
  // Refines the scene's mesh to truth_level, draws the points and finds the
  // true boundaries. Errors: invalid options (INVALID_ARGUMENT), a scene
  // without materials or whose mesh the Loop surface rejects.
  static absl::StatusOr<SurfaceScorer> Create(const Scene& scene, const SurfaceScoreOptions& options = {});

  // Errors: the reader's first error, prefixed with the point it failed at;
  // a non-finite mu (INVALID_ARGUMENT naming the point).
  absl::StatusOr<SurfaceScore> Score(const MapReader& map) const;

  // The `points` area-uniform points, then the regions' extra points.
  const std::vector<Eigen::Vector3d>& points() const { return points_; }
  const std::vector<int>& point_materials() const { return point_material_; }
  const std::vector<Eigen::Vector3d>& truth_boundary() const { return truth_boundary_; }
  // The dense level's vertices, which Score reads too (a remote reader can
  // fetch them and points() in bulk first).
  const std::vector<Eigen::Vector3d>& dense_vertices() const { return vertices_; }

 private:
  SurfaceScorer() = default;
  int NearestMaterial(double mu) const;

  Scene scene_;
  SurfaceScoreOptions options_;
  std::vector<Eigen::Vector3d> vertices_;       // the dense level's limit positions
  std::vector<std::array<int, 2>> edges_;
  std::vector<int> vertex_material_;
  std::vector<Eigen::Vector3d> points_;
  std::vector<int> point_material_, point_region_;  // region -1 = default
  int uniform_points_ = 0;                           // points_[0, uniform_points_): the area-uniform sample
  std::vector<Eigen::Vector3d> truth_boundary_;
};

// The table `surfmap-rig score` and surfmap-mapsim print, and its JSON.
std::string FormatSurfaceScore(const SurfaceScore& score, const std::string& title);
nlohmann::json SurfaceScoreToJson(const SurfaceScore& score);

}  // namespace surfmap
