// Colour maps for scalar fields (friction coefficient mu, uncertainty).
#pragma once

#include <string_view>

#include "absl/status/statusor.h"
#include "clients/render/rgb_image.h"

namespace surfmap {

enum class ColorMap {
  // dark grey (40) -> white; whiter = more friction, as in Lloyd & Pai Fig. 14.
  // Not from black, so Lambert shading still shows the shape of low-mu parts.
  kGrey,
  kViridis,  // perceptually uniform, colour-blind safe (matplotlib's viridis)
};

// "grey" (or "gray") and "viridis". Errors: INVALID_ARGUMENT naming the value.
absl::StatusOr<ColorMap> ParseColorMap(std::string_view name);
std::string_view ColorMapName(ColorMap map);

// The colour at `t` in [0, 1] (clamped; NaN gives the colour at 0).
Rgb MapColor(ColorMap map, double t);

// Normalises `value` into [0, 1] over [lo, hi] (clamped). A degenerate range
// (hi <= lo) maps everything to 0.5.
double NormalizeToRange(double value, double lo, double hi);

}  // namespace surfmap
