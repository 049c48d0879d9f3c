// JobRuntime: one mapping job's live state in memory: its parameters, the
// refined surface, the sampling plan, and the map built from the plan's
// measured sites. The database is the truth; a runtime is rebuilt from it at
// start-up, on first use, and after a failed write.
//
// Locks (see job_coordinator.h for the whole design):
//   map_mu  held while the map is rebuilt (pool threads only); taken BEFORE mu
//   mu      the plan and everything about the job's state; held only for
//           in-memory work and for queueing a store write (which never waits)
//   watchers_mu  a leaf: the listener list; never held while calling one
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "absl/base/thread_annotations.h"
#include "absl/status/status.h"
#include "server/base/mutex.h"
#include "server/jobs/job_params.h"
#include "server/map/region_map.h"
#include "server/mesh/loop_surface.h"
#include "server/plan/sampling_plan.h"
#include "storage/records.h"

namespace surfmap {

// The map at one moment: immutable, shared with readers.
struct MapSnapshot {
  std::shared_ptr<const LoopSurface> surface;
  std::shared_ptr<const RegionMap> map;    // null before the first sample
  int64_t measured_revision = 0;           // JobRuntime::measured_revision it reflects
  // The map's drag id of the first imported drag (SamplingPlan::FirstImportDrag):
  // what tells an imported drag's pieces from a site's.
  int first_import_drag = 0;
};

// A trace the job accepted, with what a Sample shows of it: the command (site,
// drag, the rig that measured it), the trace id, the fit made on arrival and
// the provenance as stored. The answers to a submission and to an import
// extend it, so a Sample is built from one form whichever way the trace came.
struct AcceptedSample {
  CommandRecord command;
  int64_t trace_id = 0;
  FitRecord fit;
  int64_t received_unix_ms = 0;
  std::string metadata_json = "{}";
};

struct JobRuntime : std::enable_shared_from_this<JobRuntime> {
  JobRuntime(int64_t id, int64_t object, JobParams p, std::shared_ptr<const LoopSurface> s, SamplingPlan pl,
             int64_t created_ms)
      : job_id(id),
        object_id(object),
        params(std::move(p)),
        surface(std::move(s)),
        created_unix_ms(created_ms),
        plan(std::move(pl)) {}

  const int64_t job_id;
  const int64_t object_id;
  const JobParams params;
  const std::shared_ptr<const LoopSurface> surface;
  const int64_t created_unix_ms;
  // Provenance given at creation (JobRecord::metadata_json): set before the
  // runtime is shared, never changed after, so read without a lock.
  std::string metadata_json = "{}";

  Mutex map_mu ABSL_ACQUIRED_BEFORE(mu);
  Mutex mu;
  SamplingPlan plan ABSL_GUARDED_BY(mu);
  // The state the queued writes leave the job in (ahead of the database while
  // a write is in flight): what the next request is checked against.
  JobState state ABSL_GUARDED_BY(mu) = JobState::kRunning;
  // The state as committed: what the job calls and watchers report.
  JobState durable_state ABSL_GUARDED_BY(mu) = JobState::kRunning;
  int64_t plan_revision ABSL_GUARDED_BY(mu) = 1;   // the stored plan's revision this plan extends
  int journal_entries ABSL_GUARDED_BY(mu) = 0;     // stored after the plan's last checkpoint
  int64_t measured_revision ABSL_GUARDED_BY(mu) = 0;  // bumped on every accepted fit (map input changed)
  // The last change (creation, state change, accepted trace, reported failure).
  int64_t updated_unix_ms ABSL_GUARDED_BY(mu) = 0;
  // The newest accepted trace (null before the first); immutable once shared.
  std::shared_ptr<const AcceptedSample> latest_sample ABSL_GUARDED_BY(mu);
  // A write failed: memory may be ahead of the database until the job is
  // reloaded. While set, requests that change the job are refused UNAVAILABLE.
  bool needs_reload ABSL_GUARDED_BY(mu) = false;
  bool reloading ABSL_GUARDED_BY(mu) = false;
  // Operator requests that arrived while the job waited to be re-read: each
  // is posted once the re-read ends, with OK or why it failed. An operator's
  // pause or cancel waits out the re-read instead of being told to retry.
  std::vector<std::function<void(absl::Status reloaded)>> after_reload ABSL_GUARDED_BY(mu);
  // SHA-256s of imported files whose write is queued, not yet durable: a
  // second import of the same file meanwhile is refused UNAVAILABLE before it
  // changes the plan (the writer would store it once, leaving memory one
  // plan change ahead of the database).
  std::set<std::string> importing_sha256 ABSL_GUARDED_BY(mu);

  // The map, rebuilt lazily on the pool.
  std::optional<RegionMap> map_builder ABSL_GUARDED_BY(map_mu);  // holds the map level's factorisation
  MapSnapshot map_snapshot ABSL_GUARDED_BY(map_mu);

  Mutex watchers_mu ABSL_ACQUIRED_AFTER(mu);
  int64_t update_revision ABSL_GUARDED_BY(watchers_mu) = 0;  // bumped on every change a watcher should see
  std::map<int64_t, std::function<void()>> listeners ABSL_GUARDED_BY(watchers_mu);
  int64_t next_listener_id ABSL_GUARDED_BY(watchers_mu) = 1;
};

inline bool IsFinalJobState(JobState state) { return state == JobState::kCompleted || state == JobState::kCancelled; }

}  // namespace surfmap
