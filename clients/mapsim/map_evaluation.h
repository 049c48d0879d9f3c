// How good is a friction map on a surface level, given the true material of
// every vertex? Accuracy of mu, of the material classification, and of where
// the boundaries between materials are.
#pragma once

#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "server/mesh/loop_surface.h"

namespace surfmap::mapsim {

struct MaterialEvaluation {
  std::string name;
  double truth_mu = 0.0;
  int vertices = 0;          // vertices of this material in the truth
  double map_mu_mean = 0.0;  // mean map mu over them (NaN when there are none)
  double map_mu_rmse = 0.0;  // RMSE of the map mu over them against truth_mu (NaN when none)
};

struct MapEvaluation {
  int vertices = 0;
  double mu_rmse = 0.0;
  double mu_max_abs_error = 0.0;
  // Share of vertices whose map mu is nearest (ClassifyNearestMaterial) to
  // the mu of their true material.
  double classification_accuracy = 0.0;
  // Boundary localisation. A truth-boundary vertex is one with a neighbour of
  // another true material; a map-boundary vertex one with a neighbour of
  // another classified material. boundary_error_mm: mean over the
  // truth-boundary vertices of the Euclidean distance (limit positions, mm) to
  // the nearest map-boundary vertex: how far off the true boundaries the map
  // puts them (a missed boundary counts with its distance to the nearest one
  // found). spurious_boundary_mm: the same from the map's boundary vertices
  // to the truth's: boundaries the map invents. NaN when either set is empty
  // (e.g. a map that classifies everything as one material).
  int truth_boundary_vertices = 0;
  int map_boundary_vertices = 0;
  double boundary_error_mm = 0.0;
  double spurious_boundary_mm = 0.0;
  std::vector<MaterialEvaluation> materials;  // in material index order
};

// `map_mu` and `truth_material` have one entry per vertex of `level`;
// `material_mus[m]` / `material_names[m]` describe material m. Errors
// (INVALID_ARGUMENT): sizes that differ from the level's vertex count, no
// materials, a material index out of range or a non-finite mu (naming the
// vertex).
absl::StatusOr<MapEvaluation> EvaluateMap(const SurfaceLevel& level, const std::vector<double>& map_mu,
                                          const std::vector<int>& truth_material,
                                          const std::vector<double>& material_mus,
                                          const std::vector<std::string>& material_names);

}  // namespace surfmap::mapsim
