// JobRuntime: one mapping job's live state in memory: its parameters, the
// refined surface, the sampling plan, and the map built from the plan's
// measured sites. The database is the truth; a runtime is rebuilt from it at
// start-up (and after a failed write).
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>

#include "server/jobs/job_params.h"
#include "server/map/friction_map.h"
#include "server/mesh/loop_surface.h"
#include "server/plan/sampling_plan.h"
#include "storage/records.h"

namespace surfmap {

// The map at one moment: immutable, shared with readers.
struct MapSnapshot {
  std::shared_ptr<const LoopSurface> surface;
  std::shared_ptr<const FrictionMap> map;  // null before the first sample
  int64_t measured_revision = 0;           // JobRuntime::measured_revision it reflects
};

// A trace the job accepted, with what a Sample shows of it: the command (site,
// drag), the trace id and the fit made on arrival (version 1).
struct AcceptedSample {
  CommandRecord command;
  int64_t trace_id = 0;
  FitRecord fit;
  int64_t received_unix_ms = 0;
};

struct JobRuntime {
  JobRuntime(int64_t id, JobParams p, std::shared_ptr<const LoopSurface> s, SamplingPlan pl)
      : job_id(id), params(std::move(p)), surface(std::move(s)), plan(std::move(pl)) {}

  const int64_t job_id;
  const JobParams params;
  const std::shared_ptr<const LoopSurface> surface;

  // Guarded by `mu`.
  std::mutex mu;
  SamplingPlan plan;
  JobState state = JobState::kRunning;
  int64_t plan_revision = 1;       // the stored plan's revision this plan extends
  int journal_entries = 0;         // stored after the plan's last checkpoint
  int64_t measured_revision = 0;   // bumped on every accepted fit (map input changed)
  int64_t update_revision = 0;     // bumped on every change a watcher should see
  // updated: the last change (creation, state change, accepted trace, reported
  // failure); the stored job row only changes with the state, so this is newer.
  int64_t created_unix_ms = 0, updated_unix_ms = 0;
  // The newest accepted trace (null before the first); immutable once shared,
  // replaced as a whole.
  std::shared_ptr<const AcceptedSample> latest_sample;
  // A write failed: memory may be ahead of the database. Atomic because a
  // store callback may report the failure on the thread that holds `mu`.
  std::atomic<bool> needs_reload{false};
  std::map<int64_t, std::function<void()>> listeners;  // watchers; called without `mu`
  int64_t next_listener_id = 1;

  // The map, rebuilt lazily; guarded by `map_mu` (not `mu`, so a rebuild does
  // not hold up rigs).
  std::mutex map_mu;
  std::optional<FrictionMap> map_builder;  // holds the surface's Laplacian
  MapSnapshot map_snapshot;
};

}  // namespace surfmap
