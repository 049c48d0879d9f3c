#include "clients/render/color_map.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <string>

#include "absl/strings/str_cat.h"

namespace surfmap {
namespace {

// viridis sampled at 17 evenly spaced points (matplotlib _viridis_data, every
// 16th entry); linear interpolation between them is visually indistinguishable
// from the full 256-entry table.
constexpr std::array<std::array<double, 3>, 17> kViridis = {{
    {0.267004, 0.004874, 0.329415}, {0.282327, 0.094955, 0.417331}, {0.278826, 0.175490, 0.483397},
    {0.258965, 0.251537, 0.524736}, {0.229739, 0.322361, 0.545706}, {0.199430, 0.387607, 0.554642},
    {0.172719, 0.448791, 0.557885}, {0.149039, 0.508051, 0.557250}, {0.127568, 0.566949, 0.550556},
    {0.120638, 0.625828, 0.533488}, {0.157851, 0.683765, 0.501686}, {0.246070, 0.738910, 0.452024},
    {0.369214, 0.788888, 0.382914}, {0.515992, 0.831158, 0.294279}, {0.678489, 0.863742, 0.189503},
    {0.845561, 0.887322, 0.099702}, {0.993248, 0.906157, 0.143936},
}};

constexpr double kGreyFloor = 40.0 / 255.0;

std::uint8_t ToByte(double v) {
  return static_cast<std::uint8_t>(std::clamp(std::lround(v * 255.0), 0L, 255L));
}

}  // namespace

absl::StatusOr<ColorMap> ParseColorMap(std::string_view name) {
  if (name == "grey" || name == "gray") return ColorMap::kGrey;
  if (name == "viridis") return ColorMap::kViridis;
  return absl::InvalidArgumentError(
      absl::StrCat("unknown colour map '", std::string(name), "' (expected 'grey' or 'viridis')"));
}

std::string_view ColorMapName(ColorMap map) {
  switch (map) {
    case ColorMap::kGrey: return "grey";
    case ColorMap::kViridis: return "viridis";
  }
  return "grey";
}

double NormalizeToRange(double value, double lo, double hi) {
  if (!(hi > lo)) return 0.5;
  return std::clamp((value - lo) / (hi - lo), 0.0, 1.0);
}

Rgb MapColor(ColorMap map, double t) {
  if (!std::isfinite(t)) t = 0.0;
  t = std::clamp(t, 0.0, 1.0);
  switch (map) {
    case ColorMap::kGrey: {
      const std::uint8_t g = ToByte(kGreyFloor + (1.0 - kGreyFloor) * t);
      return {g, g, g};
    }
    case ColorMap::kViridis: {
      const double x = t * (kViridis.size() - 1);
      const int i = std::min(static_cast<int>(x), static_cast<int>(kViridis.size()) - 2);
      const double f = x - i;
      Rgb out;
      for (int c = 0; c < 3; ++c) out[c] = ToByte((1 - f) * kViridis[i][c] + f * kViridis[i + 1][c]);
      return out;
    }
  }
  return {0, 0, 0};
}

}  // namespace surfmap
