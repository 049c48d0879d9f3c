// Pairs the reverse pass of a drag with the forward pass by position along the
// path (arc length), not by time: sample times are not aligned between the
// passes, speed is not constant and the path may be curved.
#pragma once

#include <span>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "server/estimate/drag_trace.h"

namespace surfmap {

struct PairingOptions {
  // The reverse pass must stay within max(max_offset_floor_mm,
  // max_offset_fraction * forward path length) of the forward polyline: the
  // floor allows for tip compliance and sensor noise on short paths.
  double max_offset_floor_mm = 0.5;
  double max_offset_fraction = 0.05;
  // ... and cover at least this share of the forward path.
  double min_coverage_fraction = 0.5;
  bool IsValid(std::string* why) const;
};

struct PathPairing {
  // Arc length of each forward sample along the forward polyline (first = 0), mm.
  std::vector<double> forward_s;
  // Arc length of the foot point of each reverse sample projected on the
  // forward polyline, mm (decreasing in time for a proper reverse pass, up to
  // noise).
  std::vector<double> reverse_s;
  double path_length_mm = 0.0;     // forward polyline length
  double max_offset_mm = 0.0;      // largest reverse-to-forward-polyline distance
  double covered_from_mm = 0.0;    // range of reverse_s
  double covered_to_mm = 0.0;
};

// O(n): the projection keeps a pointer into the forward polyline that only
// moves forward while the reverse samples are visited from last to first,
// looking ahead just past the distance the probe moved since the previous
// sample. INVALID_ARGUMENT when the forward pass has fewer than 2 samples or
// does not move, when the reverse pass does not retrace the forward path (a
// sample farther than the offset limit, naming it) or covers too little of it.
absl::StatusOr<PathPairing> PairPasses(std::span<const DragSample> forward,
                                       std::span<const DragSample> reverse,
                                       const PairingOptions& options = {});

// Linear interpolation over samples sorted by increasing key, queried at
// non-decreasing keys: the bracket pointer only moves forward, so a sweep over
// n queries costs O(n + m). Keys outside the range clamp to the end samples.
// `key(i)` returns the key of sample i (0 <= i < count).
class MonotoneBracket {
 public:
  explicit MonotoneBracket(int count) : count_(count) {}
  // Finds i, w with key(i) <= s <= key(i + 1) (as far as the data allow) and
  // the weight w in [0, 1] of sample i + 1. Requires count >= 1.
  template <typename KeyFn>
  void Locate(double s, const KeyFn& key, int* i, double* w) {
    if (count_ == 1) {
      *i = 0;
      *w = 0.0;
      return;
    }
    // next_ is the segment [next_, next_ + 1]; the last segment is count_ - 2.
    while (next_ + 2 < count_ && key(next_ + 1) < s) ++next_;
    const double a = key(next_), b = key(next_ + 1);
    double weight = b > a ? (s - a) / (b - a) : 0.0;
    weight = weight < 0.0 ? 0.0 : (weight > 1.0 ? 1.0 : weight);
    *i = next_;
    *w = weight;
  }

 private:
  int count_;
  int next_ = 0;
};

}  // namespace surfmap
