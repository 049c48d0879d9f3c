// What surfmap-mapsim prints and writes about mapping runs: the evidence
// table (one row per run, scored on the scene's true surface), per-region
// details, JSON, and the map as PNG (grey scale, whiter = more friction, like
// the paper's Fig. 14, with sample points and executed drag paths) and PLY.
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>
#include "absl/status/statusor.h"
#include "clients/mapsim/mapping_run.h"
#include "clients/render/map_mesh.h"
#include "clients/render/map_render.h"

namespace surfmap::mapsim {

// "boundary/regions", "adaptive L0-1 t=4/harmonic", "uniform-spread n=123/regions", ...
std::string RunLabel(const MappingRunResult& run);

// One row per run: label, samples (and the 1.5 x control vertices limit),
// share classified right overall and in the worst region, mu RMSE, boundary
// errors (map -> truth, truth -> map), time.
std::string FormatRunTable(const std::string& scene, int control_vertices, const std::vector<MappingRunResult>& runs);

// A regions map's regions, one line each: mu +- se, pooled spread, pieces
// (with roughness), share of the map, and the truth under its pieces
// ("masonite 82 %, rubber 18 %"). Empty for harmonic maps.
std::string FormatMapRegions(const MappingRunResult& run, const Scene& scene);

nlohmann::json RunToJson(const MappingRunResult& run);

// The map level coloured by the run's map mu (uncertainty = map mu std).
MapMesh RunMapMesh(const MappingBench& bench, const MappingRunResult& run);
// A dot per measured site and the rig's executed forward drag path.
MapOverlay RunOverlay(const MappingRunResult& run);

// Render options for a scene: flat scenes are seen from above (one view);
// others from the side along -x and +x (two views); the grey scale spans the
// scene's material mus, so maps of different runs compare by eye.
MapRenderOptions SceneRenderOptions(const MappingBench& bench);

absl::StatusOr<std::string> RunPng(const MappingBench& bench, const MappingRunResult& run);
absl::StatusOr<std::string> RunPly(const MappingBench& bench, const MappingRunResult& run);

}  // namespace surfmap::mapsim
