// SimulatedRig: the physics of a lab rig on a scene, no network. The scene's
// control mesh is refined to a smooth Loop surface; a probe is projected onto
// it, the drag path is traced on the surface from there along the requested
// direction, and the drag simulator (clients/sim/dragsim) turns the path and the
// scene's materials into a drag trace with the disturbances of a real rig.
//
// Deterministic: the simulator is seeded from (scene seed, options seed,
// command id), so re-executing a command gives the same trace, on any rig
// instance. Thread-safe for concurrent Execute calls (no mutable state).
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "absl/status/statusor.h"
#include "clients/sim/rig/rig_driver.h"
#include "clients/sim/rig/scene.h"
#include "clients/sim/rig/scene_truth.h"
#include "clients/sim/dragsim/drag_simulator.h"
#include "server/mesh/loop_surface.h"

namespace surfmap {

struct SimulatedRigOptions {
  int surface_level = 3;            // Loop refinement of the scene mesh (smoothness of the path);
                                    // coarser where a dense mesh needs it (LevelWithinTriangleLimit)
  std::uint64_t seed = 0;           // mixed with the scene's seed and the command id
  double path_step_mm = 0.25;       // re-projection step of the traced path
  double max_approach_mm = 10.0;    // a probe farther than this from the surface fails
  double min_segment_mm = 5.0;      // shortest drag accepted when a boundary forces shortening
  // Disturbances of the simulated rig (seed, length, speed and force are set
  // per probe from the request). DragSimOptions::Ideal() for exact physics.
  DragSimOptions simulation;

  bool IsValid(std::string* why) const;
};

// What the rig actually did, beyond the trace.
struct ProbeExecution {
  DragTrace trace;
  SurfacePath path;              // the forward path on the surface
  double length_mm = 0.0;        // executed drag length
  bool centred = false;          // the segment is centred on the requested position (false: starts there, open boundary behind)
  bool reversed = false;         // dragged opposite to the requested direction (open boundary ahead)
  bool shortened = false;        // dragged less than the requested length (open boundary both ways)
  std::string note;              // says what was adjusted and why; empty when executed as asked
  std::uint64_t seed = 0;        // the simulator seed used
  double approach_distance_mm = 0.0;  // requested position to the surface
};

class SimulatedRig : public RigDriver {
 public:
  // Refines the scene mesh. Errors: INVALID_ARGUMENT for invalid options or a
  // mesh the Loop surface rejects (message names the scene).
  static absl::StatusOr<std::unique_ptr<SimulatedRig>> Create(Scene scene, const SimulatedRigOptions& options = {});

  // The trace of ExecuteDetailed.
  absl::StatusOr<DragTrace> Execute(const ProbeRequest& request) override;

  // Errors: INVALID_ARGUMENT (ValidateProbeRequest, a drag direction along
  // the normal); FAILED_PRECONDITION when the position is more than
  // max_approach_mm from the surface or no drag of at least min_segment_mm
  // fits in either direction.
  absl::StatusOr<ProbeExecution> ExecuteDetailed(const ProbeRequest& request) const;

  // The simulator seed for a command: a fixed mix of the scene seed, the
  // options seed and the command id.
  std::uint64_t SeedFor(std::int64_t command_id) const;

  const Scene& scene() const { return scene_; }
  const LoopSurface& surface() const { return *surface_; }
  // The truth per vertex of the rig's finest level (see SceneTruthAtVertices).
  SceneTruth Truth() const { return SceneTruthAtVertices(scene_, *surface_); }

 private:
  SimulatedRig(Scene scene, SimulatedRigOptions options, std::unique_ptr<LoopSurface> surface);

  Scene scene_;
  SimulatedRigOptions options_;
  std::unique_ptr<LoopSurface> surface_;
  MaterialField material_;
};

}  // namespace surfmap
