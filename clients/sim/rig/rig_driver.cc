#include "clients/sim/rig/rig_driver.h"

#include <cmath>

#include "absl/strings/str_cat.h"

namespace surfmap {

absl::Status ValidateProbeRequest(const ProbeRequest& r) {
  if (!r.position.allFinite()) return absl::InvalidArgumentError("probe position is not finite");
  if (!r.normal.allFinite() || r.normal.norm() < 1e-9) {
    return absl::InvalidArgumentError("probe normal is zero or not finite");
  }
  if (!r.drag_direction.allFinite() || r.drag_direction.norm() < 1e-9) {
    return absl::InvalidArgumentError("probe drag_direction is zero or not finite");
  }
  if (!(r.segment_length_mm > 0.0 && r.segment_length_mm <= 500.0)) {
    return absl::InvalidArgumentError(
        absl::StrCat("probe segment_length_mm ", r.segment_length_mm, " is not in (0, 500]"));
  }
  if (!(r.speed_mm_s > 0.0 && r.speed_mm_s <= 1000.0)) {
    return absl::InvalidArgumentError(absl::StrCat("probe speed_mm_s ", r.speed_mm_s, " is not in (0, 1000]"));
  }
  if (!(r.normal_force_n > 0.0 && r.normal_force_n <= 100.0)) {
    return absl::InvalidArgumentError(
        absl::StrCat("probe normal_force_n ", r.normal_force_n, " is not in (0, 100]"));
  }
  return absl::OkStatus();
}

}  // namespace surfmap
