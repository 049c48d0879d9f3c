#include "server/codec/trace_samples_proto.h"

#include <utility>

#include "absl/strings/str_cat.h"

namespace surfmap {

namespace pb = ::surfmap::v1;

absl::StatusOr<DragTrace> DragTraceFromProto(const pb::TraceSamples& s, int max_samples) {
  const int n = s.t_size();
  const std::pair<const char*, int> columns[] = {{"x", s.x_size()},   {"y", s.y_size()},   {"z", s.z_size()},
                                                 {"fx", s.fx_size()}, {"fy", s.fy_size()}, {"fz", s.fz_size()},
                                                 {"phases", s.phases_size()}};
  if (n > max_samples) {
    return absl::ResourceExhaustedError(absl::StrCat("trace has ", n, " samples; the limit is ", max_samples));
  }
  // Every column is bounded, not only `t` (a trace with an empty `t` and a
  // huge `x` is as large as one with a huge `t`).
  for (const auto& [name, size] : columns) {
    if (size > max_samples) {
      return absl::ResourceExhaustedError(
          absl::StrCat("trace column '", name, "' has ", size, " values; the limit is ", max_samples));
    }
  }
  if (n == 0 && s.x_size() == 0) return absl::InvalidArgumentError("trace has no samples");
  for (const auto& [name, size] : columns) {
    if (size != n) {
      return absl::InvalidArgumentError(
          absl::StrCat("trace column '", name, "' has ", size, " values but 't' has ", n));
    }
  }
  if (n == 0) return absl::InvalidArgumentError("trace has no samples");
  DragTrace trace;
  trace.samples.resize(n);
  for (int i = 0; i < n; ++i) {
    DragSample& d = trace.samples[i];
    d.t = s.t(i);
    d.position = {s.x(i), s.y(i), s.z(i)};
    d.force = {s.fx(i), s.fy(i), s.fz(i)};
    switch (s.phases(i)) {
      case pb::PHASE_FORWARD: d.phase = DragPhase::kForward; break;
      case pb::PHASE_PAUSE: d.phase = DragPhase::kPause; break;
      case pb::PHASE_REVERSE: d.phase = DragPhase::kReverse; break;
      default:
        return absl::InvalidArgumentError(absl::StrCat("trace sample ", i, ": phase must be FORWARD, PAUSE or REVERSE"));
    }
  }
  return trace;
}

pb::TraceSamples DragTraceToProto(const DragTrace& trace) {
  pb::TraceSamples s;
  const int n = static_cast<int>(trace.samples.size());
  for (auto* column : {s.mutable_t(), s.mutable_x(), s.mutable_y(), s.mutable_z(), s.mutable_fx(), s.mutable_fy(),
                       s.mutable_fz()}) {
    column->Reserve(n);
  }
  s.mutable_phases()->Reserve(n);
  for (const DragSample& d : trace.samples) {
    s.add_t(d.t);
    s.add_x(d.position.x());
    s.add_y(d.position.y());
    s.add_z(d.position.z());
    s.add_fx(d.force.x());
    s.add_fy(d.force.y());
    s.add_fz(d.force.z());
    s.add_phases(d.phase == DragPhase::kForward ? pb::PHASE_FORWARD
                 : d.phase == DragPhase::kPause ? pb::PHASE_PAUSE
                                                : pb::PHASE_REVERSE);
  }
  return s;
}

}  // namespace surfmap
