#include "server/estimate/data_window.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "absl/status/status.h"
#include "absl/strings/str_format.h"

namespace surfmap {
namespace {

struct SpeedRange {
  double from_mm = 0.0;
  double to_mm = 0.0;
  bool empty = true;
};

// Range of arc length where the smoothed speed of one pass is at least
// `fraction` of its median. `speed` is scratch space of size samples.size().
SpeedRange FastRange(std::span<const DragSample> samples, const std::vector<double>& s,
                     double smoothing_s, double fraction, std::vector<double>& speed) {
  const int n = static_cast<int>(samples.size());
  SpeedRange range;
  if (n < 2) return range;
  const double dt = (samples[n - 1].t - samples[0].t) / (n - 1);
  const int h = std::max(1, static_cast<int>(std::lround(smoothing_s / dt)));
  speed.resize(n);
  for (int i = 0; i < n; ++i) {
    const int a = std::max(0, i - h), b = std::min(n - 1, i + h);
    speed[i] = std::abs(s[b] - s[a]) / (samples[b].t - samples[a].t);
  }
  std::vector<double> sorted = speed;
  std::nth_element(sorted.begin(), sorted.begin() + n / 2, sorted.end());
  const double threshold = fraction * sorted[n / 2];
  int first = -1, last = -1;
  for (int i = 0; i < n; ++i) {
    if (speed[i] >= threshold) {
      if (first < 0) first = i;
      last = i;
    }
  }
  if (first < 0 || !(threshold > 0.0)) return range;
  range.from_mm = std::min(s[first], s[last]);
  range.to_mm = std::max(s[first], s[last]);
  range.empty = false;
  return range;
}

}  // namespace

bool WindowOptions::IsValid(std::string* why) const {
  auto fail = [&](const char* message) {
    if (why) *why = message;
    return false;
  };
  if (!(min_speed_fraction >= 0.0 && min_speed_fraction < 1.0)) {
    return fail("min_speed_fraction must be in [0, 1)");
  }
  if (!(smoothing_s >= 0.0)) return fail("smoothing_s must be >= 0");
  if (!(trim_fraction >= 0.0 && trim_fraction < 0.5)) return fail("trim_fraction must be in [0, 0.5)");
  return true;
}

absl::StatusOr<DataWindow> ChooseDataWindow(std::span<const DragSample> forward,
                                            std::span<const DragSample> reverse,
                                            const PathPairing& pairing,
                                            const WindowOptions& options) {
  std::vector<double> scratch;
  scratch.reserve(std::max(forward.size(), reverse.size()));
  const SpeedRange fwd = FastRange(forward, pairing.forward_s, options.smoothing_s,
                                   options.min_speed_fraction, scratch);
  const SpeedRange rev = FastRange(reverse, pairing.reverse_s, options.smoothing_s,
                                   options.min_speed_fraction, scratch);
  if (fwd.empty || rev.empty) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "no data window: the %s pass never moves at %.0f%% of its median speed",
        fwd.empty ? "forward" : "reverse", 100.0 * options.min_speed_fraction));
  }
  const double common_from = std::max(0.0, pairing.covered_from_mm);
  const double common_to = std::min(pairing.path_length_mm, pairing.covered_to_mm);
  const double trim = options.trim_fraction * (common_to - common_from);
  DataWindow window;
  window.start_mm = std::max({common_from + trim, fwd.from_mm, rev.from_mm});
  window.end_mm = std::min({common_to - trim, fwd.to_mm, rev.to_mm});
  if (!(window.end_mm > window.start_mm)) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "no data window: common path %.3f..%.3f mm trimmed by %.3f mm, forward fast range "
        "%.3f..%.3f mm and reverse fast range %.3f..%.3f mm do not overlap",
        common_from, common_to, trim, fwd.from_mm, fwd.to_mm, rev.from_mm, rev.to_mm));
  }
  return window;
}

}  // namespace surfmap
