// Numbers as people read them in tables: a value that prints as zero at the
// shown precision prints "0.00", never "-0.00" (a tiny negative residual, or
// IEEE negative zero, is not a negative quantity worth a sign).
#pragma once

#include <cmath>

namespace surfmap::cli {

// `value`, or +0.0 when it rounds to zero at `decimals` places; pass the
// result to "%.<decimals>f". NaN and infinities pass through.
inline double Shown(double value, int decimals) {
  if (!std::isfinite(value)) return value;
  const double scale = std::pow(10.0, decimals);
  return std::round(value * scale) == 0.0 ? 0.0 : value;
}

}  // namespace surfmap::cli
