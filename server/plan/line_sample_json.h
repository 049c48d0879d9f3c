// The compact JSON form of a line sample (estimate/line_sample.h) that the
// plan keeps for every measured drag and the plan journal carries:
//
//   {"s": [mm, ...], "p": [[x, y, z], ...],
//    "pieces": [{"from": mm, "to": mm, "cs": bool, "ce": bool, "mu": x,
//                "sd": x, "se": x, "n": x, "k": [k1, ...], "sigma": x,
//                "rows": n}, ...],
//    "ps": [mm, ...], "pmu": [mu, ...]}
//
// s / p: the path (positions along it, points); per piece its extent, whether
// a change bounds its start (cs) / end (ce), mu, per-pair spread (sd), mu's
// standard error (se), effective pairs (n) and, when it has its own
// roughness, the reflection coefficients (k) and sigma (otherwise [] and 0),
// and the values behind that fit (rows; LinePiece::roughness_rows; absent in
// plans saved before it existed, read as 0). ps / pmu: the per-pair friction
// series (LineSample::pair_s_mm, pair_mu; absent when empty, and in plans
// saved before it was kept).
// Doubles round-trip exactly, so a replayed plan decides as the original did.
#pragma once

#include <string>

#include <nlohmann/json.hpp>
#include "absl/status/statusor.h"
#include "server/estimate/line_sample.h"

namespace surfmap {

nlohmann::json LineSampleToJson(const LineSample& line);
// INVALID_ARGUMENT naming the field (prefixed with `where`) for malformed
// input or a line sample that LineSample::Validate rejects.
absl::StatusOr<LineSample> LineSampleFromJson(const nlohmann::json& json, const std::string& where);

}  // namespace surfmap
