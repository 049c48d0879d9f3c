#include "server/jobs/stored_trace.h"

namespace surfmap {

std::vector<StoredSample> ToStoredSamples(const DragTrace& trace) {
  std::vector<StoredSample> out;
  out.reserve(trace.samples.size());
  for (const DragSample& d : trace.samples) {
    StoredSample s;
    s.t = d.t;
    s.x = d.position.x();
    s.y = d.position.y();
    s.z = d.position.z();
    s.fx = d.force.x();
    s.fy = d.force.y();
    s.fz = d.force.z();
    s.phase = static_cast<uint8_t>(d.phase);
    out.push_back(s);
  }
  return out;
}

DragTrace FromStoredSamples(const std::vector<StoredSample>& samples) {
  DragTrace trace;
  trace.samples.reserve(samples.size());
  for (const StoredSample& s : samples) {
    DragSample d;
    d.t = s.t;
    d.position = {s.x, s.y, s.z};
    d.force = {s.fx, s.fy, s.fz};
    d.phase = static_cast<DragPhase>(s.phase);
    trace.samples.push_back(d);
  }
  return trace;
}

}  // namespace surfmap
