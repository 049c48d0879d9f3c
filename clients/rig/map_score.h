// How good is a measured map? A map file (surfmap map get --format json, with
// its mesh) against the truth of the scene it was measured on: the material of
// every map vertex is looked up in the scene at the vertex position.
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>
#include "absl/status/statusor.h"
#include "clients/remote/map_json.h"
#include "clients/sim/rig/scene.h"

namespace surfmap::rig {

// The map over one scene region (or the default material outside every region).
struct RegionScore {
  std::string name;        // "sandpaper (regions[0])", "glass (default)"
  std::string material;
  double truth_mu = 0.0;
  int vertices = 0;         // map vertices in the region (first region containing them)
  int vertices_with_mu = 0;
  double map_mu_mean = 0.0; // NaN without values
  double map_mu_std = 0.0;
};

struct MapScore {
  int vertices = 0;
  int vertices_with_mu = 0;      // the rest (NaN) are left out of every statistic
  int samples = 0;
  double mu_rmse = 0.0;          // over vertices with a value, against the truth's mu
  double mu_max_abs_error = 0.0;
  // Share of vertices whose map mu is nearest to the mu of their true material
  // (among the scene's materials; ties go to the lower material index).
  double classification_accuracy = 0.0;
  std::vector<RegionScore> regions;  // scene regions in file order, then the default material
};

// FAILED_PRECONDITION when the map has no vertex positions (fetched without
// its mesh) or no vertex with a value.
absl::StatusOr<MapScore> ScoreMap(const Scene& scene, const cli::MapDocument& map);

// The table printed by `surfmap-rig score`.
std::string FormatMapScore(const MapScore& score, const std::string& scene_name);
nlohmann::json MapScoreToJson(const MapScore& score, const std::string& scene_name);

}  // namespace surfmap::rig
