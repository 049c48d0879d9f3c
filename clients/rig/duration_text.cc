#include "clients/rig/duration_text.h"

#include <cmath>
#include <string>

#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"

namespace surfmap::rig {

absl::StatusOr<double> ParseDurationSeconds(std::string_view text) {
  auto bad = [&]() {
    return absl::InvalidArgumentError(absl::StrCat("'", absl::string_view(text.data(), text.size()),
                                                   "' is not a duration (e.g. 300, 90s, 5min, 1.5h)"));
  };
  std::string_view number = text;
  while (!number.empty() && number.back() == ' ') number.remove_suffix(1);
  double scale = 1.0;
  size_t unit_start = number.find_first_not_of("0123456789.+-eE ");
  // "e" is part of a number ("1e3") but not of a unit we accept.
  std::string_view unit = unit_start == std::string_view::npos ? std::string_view() : number.substr(unit_start);
  if (!unit.empty()) {
    if (unit == "s") {
      scale = 1.0;
    } else if (unit == "m" || unit == "min") {
      scale = 60.0;
    } else if (unit == "h") {
      scale = 3600.0;
    } else {
      return bad();
    }
    number = number.substr(0, unit_start);
  }
  while (!number.empty() && number.back() == ' ') number.remove_suffix(1);
  double value = 0.0;
  if (number.empty() || !absl::SimpleAtod(absl::string_view(number.data(), number.size()), &value) ||
      !std::isfinite(value) || value < 0) {
    return bad();
  }
  return value * scale;
}

}  // namespace surfmap::rig
