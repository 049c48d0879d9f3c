// The texture model per region as JSON, for renderers that want materials
// rather than vertices (docs/texture-model.md documents every member):
//
//   {"format": "surfmap.texture-model.v1", "job_id": 3, "level": 3,
//    "units": {"length": "mm", "force": "N", "mu": "1", "sigma": "N", "grid_step": "mm"},
//    "grid_step_mm": 0.1,
//    "model": "<the force model in one line>",
//    "vertex_count": 642, "unassigned_vertex_count": 0,
//    "regions": [{"region": 0, "mu": 0.31, "mu_se": 0.004, "mu_spread": 0.01,
//                 "piece_count": 12, "roughness_piece_count": 10,
//                 "ar_order": 2, "ar_coefficients": [0.6, 0.25], "reflection": [0.8, 0.25],
//                 "sigma": 0.11, "roughness_std_n": 0.21, "dominant_wavelength_mm": null,
//                 "area_mm2": 812.5, "vertex_count": 233}, ...]}
#pragma once

#include <cstdint>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>
#include "absl/status/statusor.h"
#include "server/haptics/texture_map.h"

namespace surfmap::haptics {

inline constexpr std::string_view kTextureModelFormat = "surfmap.texture-model.v1";

// The JSON document of `map`'s regions. Errors: ValidateTextureMap's.
absl::StatusOr<nlohmann::json> TextureModelToJson(const TextureMap& map);

struct TextureModel {
  std::int64_t job_id = 0;
  int level = 0;
  double grid_step_mm = 0.1;
  int vertex_count = 0;
  std::vector<TextureRegion> regions;
};

// Reads a texture-model document back. Errors: INVALID_ARGUMENT naming
// `source` and the JSON path (wrong format, missing or mistyped members,
// ar_coefficients and reflection of different lengths).
absl::StatusOr<TextureModel> TextureModelFromJson(const nlohmann::json& json, std::string_view source);

}  // namespace surfmap::haptics
