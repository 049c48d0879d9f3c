// TextureMap: a friction/roughness map as a haptic model, independent of the
// API (no proto, no gRPC): the mesh of one map level with every per-vertex
// quantity, and the material regions with their pooled texture. It is what the
// exporters write (PLY, glTF, texture JSON) and what TextureRenderer loads.
//
// Units: positions in mm, forces in N; mu and reflection coefficients are
// dimensionless; the AR model runs on a grid of `grid_step_mm` of arc length:
//   F_friction = mu F_n,   r(k) = a1 r(k-1) + ... + ap r(k-p) + sigma e(k),
//   e ~ N(0, 1), k = round(s / grid_step_mm), s the arc length slid (mm).
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>
#include "absl/status/status.h"

namespace surfmap::haptics {

// One material region of the map (the API's MapRegion).
struct TextureRegion {
  int region = 0;
  double mu = 0.0;
  double mu_se = 0.0;
  double mu_spread = 0.0;
  int piece_count = 0;
  int roughness_piece_count = 0;
  std::vector<double> reflection;       // k1..kp; empty without roughness
  std::vector<double> ar_coefficients;  // a1..ap from `reflection`
  double sigma = 0.0;                   // N; 0 without roughness
  double area_mm2 = 0.0;
};

struct TextureMap {
  std::int64_t job_id = 0;
  int level = 0;
  double grid_step_mm = 0.1;  // the AR model's arc-length grid
  std::vector<Eigen::Vector3d> positions;      // mm
  std::vector<Eigen::Vector3d> normals;        // unit, outward; empty = from the faces
  std::vector<std::array<int, 3>> triangles;   // counter-clockwise seen from outside
  // Per vertex. NaN = unknown (no data reachable). Roughness arrays are empty
  // when the map has no roughness; sigma 0 = no roughness fit there.
  std::vector<double> mu, mu_std;
  std::vector<double> sigma, a1, a2;
  // Reflection coefficients per vertex, vertex-major: reflection[v * ar_order + j]
  // is k_(j+1) of vertex v (0 <= j < ar_order). Empty when ar_order == 0.
  int ar_order = 0;
  std::vector<double> reflection;
  std::vector<int> region;                     // index into `regions`, -1 = none; may be empty
  std::vector<double> boundary_probability;    // may be empty
  std::vector<TextureRegion> regions;

  int vertex_count() const { return static_cast<int>(positions.size()); }
  bool has_roughness() const { return ar_order > 0; }
  double ReflectionAt(int vertex, int j) const { return reflection[static_cast<size_t>(vertex) * ar_order + j]; }
};

// INVALID_ARGUMENT naming the first problem: no vertices or triangles,
// non-finite positions or normals, triangle indices out of range, per-vertex
// arrays of the wrong length (mu and mu_std must have one value per vertex;
// sigma/a1/a2/region/boundary_probability one or none; reflection
// ar_order per vertex), ar_order outside 0..20, grid_step_mm not finite and
// > 0, infinite values, negative sigma, region indices outside -1..regions-1.
absl::Status ValidateTextureMap(const TextureMap& map);

// Fills `reflection` (ar_order = 2) from the per-vertex a1, a2 (Levinson
// step-down; unknown or sigma-0 vertices get k = 0). No-op without a1/a2.
void FillReflectionFromAr(TextureMap& map);

// Names of the per-vertex quantities an exporter writes, for messages and
// docs: "mu", "mu_std", "sigma", "a1", "a2", "k1".."kp", "region",
// "boundary_probability".
std::vector<std::string> PerVertexAttributeNames(const TextureMap& map);

}  // namespace surfmap::haptics
