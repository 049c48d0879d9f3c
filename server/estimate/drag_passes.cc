#include "server/estimate/drag_passes.h"

#include <cmath>
#include <string>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"

namespace surfmap {
namespace {

// Far beyond any drag (a rig spans metres and pushes with newtons), and small
// enough that nothing the fit derives overflows: squared norms and products of
// forces, path lengths summed over a million samples. Beyond them a finite
// value still gave an infinite path length or a NaN mu with an OK status.
constexpr double kMaxAbsPositionMm = 1e9;
constexpr double kMaxAbsForceN = 1e9;

}  // namespace

absl::StatusOr<DragPasses> SplitDragPasses(const DragTrace& trace) {
  const auto& samples = trace.samples;
  std::size_t counts[3] = {0, 0, 0};
  for (std::size_t i = 0; i < samples.size(); ++i) {
    const DragSample& s = samples[i];
    if (!std::isfinite(s.t) || !s.position.allFinite() || !s.force.allFinite()) {
      return absl::InvalidArgumentError(
          absl::StrCat("sample ", i, ": time, position or force is not finite"));
    }
    for (int k = 0; k < 3; ++k) {
      if (std::abs(s.position[k]) > kMaxAbsPositionMm) {
        return absl::InvalidArgumentError(absl::StrCat("sample ", i, ": position coordinate ", s.position[k],
                                                       " mm is outside -1e9..1e9 mm"));
      }
      if (std::abs(s.force[k]) > kMaxAbsForceN) {
        return absl::InvalidArgumentError(
            absl::StrCat("sample ", i, ": force component ", s.force[k], " N is outside -1e9..1e9 N"));
      }
    }
    if (i > 0) {
      if (!(s.t > samples[i - 1].t)) {
        return absl::InvalidArgumentError(absl::StrCat("sample ", i, ": time ", s.t,
                                                       " s does not increase (previous ",
                                                       samples[i - 1].t, " s)"));
      }
      if (static_cast<int>(s.phase) < static_cast<int>(samples[i - 1].phase)) {
        return absl::InvalidArgumentError(
            absl::StrCat("sample ", i, ": phase '", std::string(DragPhaseName(s.phase)), "' after '",
                         std::string(DragPhaseName(samples[i - 1].phase)),
                         "': phases must come in the order fwd, pause, rev"));
      }
    }
    ++counts[static_cast<int>(s.phase)];
  }
  if (counts[0] == 0) return absl::InvalidArgumentError("trace has no forward (fwd) samples");
  if (samples.front().phase != DragPhase::kForward) {
    return absl::InvalidArgumentError("sample 0: a trace starts with its forward (fwd) pass");
  }
  if (counts[2] == 0) return absl::InvalidArgumentError("trace has no reverse (rev) samples");
  DragPasses passes;
  const std::span<const DragSample> all(samples);
  passes.forward = all.subspan(0, counts[0]);
  passes.pause_offset = counts[0];
  passes.pause = all.subspan(counts[0], counts[1]);
  passes.reverse_offset = counts[0] + counts[1];
  passes.reverse = all.subspan(passes.reverse_offset, counts[2]);
  return passes;
}

}  // namespace surfmap
