// Durations on the command line: "300", "300s", "90 s", "5m", "5min", "1.5h".
#pragma once

#include <string_view>

#include "absl/status/statusor.h"

namespace surfmap::rig {

// Seconds. A bare number is seconds; units s, m/min, h. INVALID_ARGUMENT
// naming the text for anything else, negative or non-finite values.
absl::StatusOr<double> ParseDurationSeconds(std::string_view text);

}  // namespace surfmap::rig
