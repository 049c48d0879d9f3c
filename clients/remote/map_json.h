// The map file of `surfmap map get --format json`, read back by
// `surfmap-rig score` and by scripts:
//
//   {"format": "surfmap.map.v1", "job_id": 3, "level": 3, "vertex_count": 642,
//    "vertices": {"position": [[x,y,z],...] (mm), "normal": [[...]...],
//                 "mu": [...], "mu_uncertainty": [...], "sigma": [...], "a1": [...], "a2": [...],
//                 "region": [...] (index into "regions"; -1: no data reachable)},
//    "triangles": [[i,j,k],...],
//    "regions": [{...MapRegion..., "pieces": [{...MapRegionPiece...}]}],
//    "samples": [{"trace_id", "command_id", "site": {"level", "vertex"}, "position": [..],
//                 "drag_direction": [..], "segment_length_mm", "mu", "mu_std", "fit": {...}}],
//    "summary": {"samples", "samples_per_level": {"0": n,...}, "mu_min", "mu_max", "mu_mean",
//                "mu_uncertainty_mean", "sample_mu_min", "sample_mu_max"},
//    "job": {...JobInfo...}}
//
// position/normal/triangles are present when the map was fetched with its
// mesh. Unknown values (NaN) are written as null and read back as NaN. The
// fit object and the regions are the API's messages in protobuf JSON
// (snake_case names); scripts and the Python client's writer (map_file.py)
// may leave the regions out.
#pragma once

#include <array>
#include <cstdint>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>
#include "absl/status/statusor.h"
#include "proto/surfmap/v1/surfmap.pb.h"

namespace surfmap::cli {

inline constexpr std::string_view kMapJsonFormat = "surfmap.map.v1";

// `job` may be null (then no "job" member).
nlohmann::json MapToJson(const surfmap::v1::GetMapResponse& response, const surfmap::v1::JobInfo* job);

struct MapSampleRecord {
  std::int64_t trace_id = 0;
  int site_level = 0;
  int site_vertex = 0;
  std::array<double, 3> position{};
  std::array<double, 3> drag_direction{};
  double segment_length_mm = 0.0;
  double mu = 0.0;
  double mu_std = 0.0;
};

// The parts of a map file its readers use.
struct MapDocument {
  std::int64_t job_id = 0;
  int level = 0;
  std::vector<std::array<double, 3>> positions;  // empty without a mesh
  std::vector<std::array<int, 3>> triangles;
  std::vector<double> mu;                         // per vertex, NaN = unknown
  std::vector<double> mu_uncertainty;
  // Roughness per vertex (NaN = unknown there); empty when the map has none.
  std::vector<double> a1, a2, sigma;
  std::vector<MapSampleRecord> samples;
};

// Errors (INVALID_ARGUMENT, prefixed with `source`): not a map file (format),
// missing or mistyped members (named by JSON path), per-vertex arrays whose
// lengths differ from vertex_count.
absl::StatusOr<MapDocument> MapDocumentFromJson(const nlohmann::json& json, std::string_view source);

}  // namespace surfmap::cli
