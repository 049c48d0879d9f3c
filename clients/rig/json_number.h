// A measured double as JSON: the number, or null where it is not finite (JSON
// has no NaN or infinity). Shared by the rig client's JSON writers.
#pragma once

#include <cmath>

#include <nlohmann/json.hpp>

namespace surfmap::rig {

inline nlohmann::json FiniteOrNull(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); }

}  // namespace surfmap::rig
