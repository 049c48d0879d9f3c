// JobCoordinator: the service's domain logic, below gRPC: objects, jobs and
// their plans, the rigs' protocol, maps, refits and watchers, over a Store.
// It composes parts with one job each:
//
//   JobRegistry    the jobs in memory; loading; restoring after a failed write
//   JobSteering    create, read, pause/resume/cancel
//   ProbeProtocol  lease, submit a trace, report a failure
//   CurrentMap     the map of a job's measured sites (job_map.h)
//   RefitJobTraces paged re-estimation (job_refit.h)
//   job_watchers   listeners of WatchJob streams
//   JobReads       objects, samples and traces from the store
//
// ---- Concurrency: why nothing here can deadlock or stall ----
//
// Threads: gRPC callback threads (handlers), the store's writer thread, the
// completion queue (JobExecutors::completions, one thread, FIFO) and the
// worker pool (JobExecutors::work, bounded).
//
// 1. Nobody waits on storage while holding a lock. A change is decided under
//    the job's lock (runtime.mu), its store write is QUEUED under that lock
//    (queueing never waits: the writer's own lock is held only to push), and
//    the lock is released. Memory runs ahead of the database between queueing
//    and commit; writes of one job commit in queue order, so the database
//    passes through the same states. What callers are told (job state,
//    acknowledgements) is applied only once durable.
// 2. Store callbacks only post. Every callback posts its continuation to the
//    completion queue and returns; the writer thread never takes a job lock,
//    never calls a listener, never answers an RPC itself.
// 3. Lock order is fixed and shallow: runtime.map_mu -> runtime.mu; registry
//    and surface-cache locks and runtime.watchers_mu are leaves (nothing is
//    called while they are held). No lock is held while calling a callback,
//    a listener, or the store's blocking calls.
// 4. Handlers never block on long work: fits, map builds, refits, job loads
//    and recomputed series run on the bounded pool (UNAVAILABLE when it is
//    full); cheap reads (a job from memory, an indexed row) stay on the
//    handler and use read connections that bulk reads cannot all take.
// 5. Watchers are woken, not fed: a listener sets a dirty flag and posts a
//    build of the next update to the pool (see JobWatchReactor).
//
// The clang thread-safety annotations (ABSL_GUARDED_BY and friends) on every
// lock are checked by scripts/check-thread-safety.sh; the fault-injecting
// store (storage/testing) tests rules 1-2 with held, failed, inline and late
// writes; the chaos soak (tests/chaos) mixes every kind of call.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "server/jobs/job_executors.h"
#include "server/jobs/job_map.h"
#include "server/jobs/job_reads.h"
#include "server/jobs/job_refit.h"
#include "server/jobs/job_registry.h"
#include "server/jobs/job_steering.h"
#include "server/jobs/probe_protocol.h"
#include "server/jobs/provenance.h"
#include "server/jobs/trace_import.h"
#include "server/jobs/rig_registrations.h"
#include "server/mesh/control_mesh.h"
#include "server/mesh/mesh_repair.h"
#include "storage/store.h"

namespace surfmap {

// What an upload made of the file.
struct UploadedObject {
  ObjectRecord object;
  std::vector<MeshRepairNote> repairs;
  std::vector<std::string> warnings;
  double mm_per_unit = 1.0;
  Eigen::Vector3d extent_mm = Eigen::Vector3d::Zero();
  double area_mm2 = 0.0;
};

struct CoordinatorOptions {
  int64_t default_lease_ms = 60'000;
  size_t retained_finished_jobs = 8;  // finished jobs kept in memory after use
};

class JobCoordinator {
 public:
  JobCoordinator(Store* store, JobExecutors executors, CoordinatorOptions options = {});

  // Loads every running or paused job (finished ones load on first use), and
  // the rigs' registrations.
  absl::Status LoadJobs() {
    if (absl::Status s = rigs_.Load(); !s.ok()) return s;
    return registry_.LoadActiveJobs();
  }

  // ---- Objects (pool threads: parsing and refining take long) ----
  // The mesh is parsed, validated and refined to level 1 before it is stored,
  // so a stored object always has a usable surface.
  absl::StatusOr<ObjectRecord> UploadObject(const std::string& name, MeshFormat format, std::string bytes);
  // With units: innocuous defects are repaired (mesh_repair.h) and the mesh
  // is scaled to mm; its size is checked (mesh_units.h): refused when
  // implausible in units the caller stated, a warning when `unit_stated` is
  // false (mm assumed). A repaired or scaled mesh is stored as OBJ in mm.
  struct UploadOptions {
    double mm_per_unit = 1.0;
    std::string unit_text = "mm";
    bool unit_stated = false;
    // The flat facets are the surface (ObjectRecord::surface "facets").
    bool facets = false;
  };
  absl::StatusOr<UploadedObject> UploadObject(const std::string& name, MeshFormat format, std::string bytes,
                                              const UploadOptions& options);
  // With provenance (stored as the object's metadata_json, provenance.h).
  absl::StatusOr<UploadedObject> UploadObject(const std::string& name, MeshFormat format, std::string bytes,
                                              const UploadOptions& options, const Provenance& provenance);
  absl::StatusOr<std::shared_ptr<const LoopSurface>> Surface(int64_t object_id, int level,
                                                             double site_spacing_mm = 0);

  // ---- Jobs ----
  absl::StatusOr<JobSnapshot> CreateJob(const JobParams& params, const std::string& metadata_json = "{}") {
    return steering_.CreateJob(params, metadata_json);
  }
  // Cheap when IsJobLoaded(job_id); otherwise it loads the job (a pool thread).
  absl::StatusOr<JobSnapshot> GetJob(int64_t job_id) { return steering_.GetJob(job_id); }
  absl::StatusOr<std::vector<JobSnapshot>> ListJobs(int64_t object_id) { return steering_.ListJobs(object_id); }
  void SetJobState(int64_t job_id, JobState target, JobSteering::SnapshotCallback done) {
    steering_.SetJobState(job_id, target, std::move(done));
  }
  absl::StatusOr<std::vector<SiteRecord>> PlanSites(int64_t job_id, PlanProgress* progress) {
    return steering_.PlanSites(job_id, progress);
  }
  absl::StatusOr<LeasedCounts> LeasedCommands(int64_t job_id, const PlanProgress& progress) {
    return steering_.LeasedCommands(job_id, progress);
  }
  bool IsJobLoaded(int64_t job_id) { return registry_.Find(job_id) != nullptr; }
  // The job's surface (loads the job if needed).
  absl::StatusOr<std::shared_ptr<const LoopSurface>> JobSurface(int64_t job_id);

  // ---- Probing ----
  ProbeProtocol& probes() { return probes_; }
  // Drags recorded elsewhere, imported into a job's map (trace_import.h).
  TraceImporter& imports() { return imports_; }

  // ---- The map and refits (pool threads) ----
  absl::StatusOr<MapSnapshot> Map(int64_t job_id);
  absl::StatusOr<RefitOutcome> RefitJob(int64_t job_id, const FitOptions& options) {
    return RefitJobTraces(*store_, rigs_, job_id, options);
  }

  // ---- Watchers ----
  // `listener` runs after every change of the job, with no lock held, never
  // on the store's thread; it must not block. Loads the job if needed.
  struct WatchHandle {
    std::shared_ptr<JobRuntime> runtime;  // keeps the watched job's runtime
    int64_t listener = 0;
  };
  absl::StatusOr<WatchHandle> Watch(int64_t job_id, std::function<void()> listener);
  static void Unwatch(const WatchHandle& handle);
  // The job's update revision (bumped with every change watchers see). The
  // job must be in memory (it is while watched).
  absl::StatusOr<int64_t> UpdateRevision(int64_t job_id);

  // ---- Reads ----
  JobReads& reads() { return reads_; }
  // ---- Rig registrations (frames and calibration) ----
  RigRegistrations& rigs() { return rigs_; }
  JobRegistry& registry() { return registry_; }

 private:
  Store* const store_;
  JobRegistry registry_;
  RigRegistrations rigs_;
  JobSteering steering_;
  ProbeProtocol probes_;
  TraceImporter imports_;
  JobReads reads_;
};

}  // namespace surfmap
