#include "tests/bench/trace_templates.h"

#include <Eigen/Geometry>
#include "clients/sim/dragsim/drag_geometry.h"
#include "clients/sim/dragsim/drag_simulator.h"
#include "clients/sim/dragsim/material.h"

namespace surfmap::bench {

absl::StatusOr<std::vector<DragTrace>> MakeTraceTemplates(int count, std::uint64_t seed, double length_mm,
                                                          double sample_rate_hz) {
  std::vector<DragTrace> out;
  const DragGeometry geometry =
      PlaneGeometry(Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitZ(), length_mm + 1.0);
  for (int i = 0; i < count; ++i) {
    DragSimOptions options;
    options.seed = seed + static_cast<std::uint64_t>(i);
    options.length_mm = length_mm;
    options.sample_rate_hz = sample_rate_hz;
    absl::StatusOr<DragSimResult> result = SimulateDrag(geometry, UniformMaterial(kRubber), options);
    if (!result.ok()) return result.status();
    out.push_back(std::move(result->trace));
  }
  return out;
}

surfmap::v1::TraceSamples PlaceTrace(const DragTrace& local, const surfmap::v1::ProbeCommand& command) {
  const Eigen::Vector3d p(command.position().x(), command.position().y(), command.position().z());
  Eigen::Vector3d n(command.normal().x(), command.normal().y(), command.normal().z());
  Eigen::Vector3d d(command.drag_direction().x(), command.drag_direction().y(), command.drag_direction().z());
  if (n.norm() < 1e-12) n = Eigen::Vector3d::UnitZ();
  n.normalize();
  d -= d.dot(n) * n;  // keep the frame orthonormal whatever the command says
  if (d.norm() < 1e-9) d = n.unitOrthogonal();
  d.normalize();
  Eigen::Matrix3d rotation;
  rotation.col(0) = d;
  rotation.col(1) = n.cross(d);
  rotation.col(2) = n;

  surfmap::v1::TraceSamples out;
  const int size = static_cast<int>(local.samples.size());
  for (auto* column : {out.mutable_t(), out.mutable_x(), out.mutable_y(), out.mutable_z(), out.mutable_fx(),
                       out.mutable_fy(), out.mutable_fz()}) {
    column->Reserve(size);
  }
  out.mutable_phases()->Reserve(size);
  for (const DragSample& s : local.samples) {
    const Eigen::Vector3d x = p + rotation * s.position;
    const Eigen::Vector3d f = rotation * s.force;
    out.add_t(s.t);
    out.add_x(x.x());
    out.add_y(x.y());
    out.add_z(x.z());
    out.add_fx(f.x());
    out.add_fy(f.y());
    out.add_fz(f.z());
    out.add_phases(s.phase == DragPhase::kForward ? surfmap::v1::PHASE_FORWARD
                   : s.phase == DragPhase::kPause ? surfmap::v1::PHASE_PAUSE
                                                  : surfmap::v1::PHASE_REVERSE);
  }
  return out;
}

}  // namespace surfmap::bench
