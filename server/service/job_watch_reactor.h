// WatchJob: one reactor per stream.
//
// A change of the job wakes the stream; it never feeds it. The job's listener
// (called from the completion queue or the pool, never the store's thread)
// only sets `dirty` and, when no build is under way, posts one to the pool.
// The build (the job, its newest sample and, if asked, the map: possibly a
// rebuild of tens of ms) runs on the pool WITHOUT the stream's lock; the lock
// is taken only to hand the finished message to gRPC.
//
// One write is in flight at a time, and at most one built update waits behind
// it; changes meanwhile are coalesced into the next build, so a slow client
// costs one pending message and no CPU, never a growing queue.
//
// Builds are paced: a stream gets at most one update per kMapUpdateInterval
// when it carries the map (a rebuild and the whole map serialized: tens of
// ms on a large object) and per kUpdateInterval otherwise, whatever the rate
// of traces, so dashboards cost the rigs a bounded share of the machine. A
// change during the pause is delivered when it ends.
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <optional>

#include "absl/base/thread_annotations.h"
#include "server/base/mutex.h"
#include "server/service/grpc_services.h"
#include "server/service/watch_update_cache.h"

namespace surfmap {

class JobWatchReactor final : public grpc::ServerWriteReactor<pb::JobUpdate> {
 public:
  // Starts the stream (subscribes on the pool: it may load the job).
  static JobWatchReactor* Start(const ServiceContext& services, int64_t job_id, bool include_map);

  void OnWriteDone(bool ok) override;
  void OnCancel() override;
  void OnDone() override;

 private:
  // The stream's state. Listeners and pool tasks hold it and find the
  // reactor gone (null) after OnDone.
  struct Stream {
    Stream(const ServiceContext& s, int64_t job, bool map) : services(s), job_id(job), include_map(map) {}
    const ServiceContext services;
    const int64_t job_id;
    const bool include_map;
    std::atomic<bool> dirty{false};     // the job changed since the last build started
    std::atomic<bool> building{false};  // a build is scheduled, posted or running
    std::atomic<int64_t> next_build_ns{0};  // steady clock: no build before this

    Mutex mu;
    JobWatchReactor* reactor ABSL_GUARDED_BY(mu) = nullptr;
    JobCoordinator::WatchHandle handle ABSL_GUARDED_BY(mu);
    // The message gRPC is writing (shared with other streams of the job: see
    // WatchUpdateCache), and the one waiting behind it.
    std::shared_ptr<const pb::JobUpdate> in_flight ABSL_GUARDED_BY(mu);
    std::shared_ptr<const pb::JobUpdate> next ABSL_GUARDED_BY(mu);
    bool next_final ABSL_GUARDED_BY(mu) = false;
    bool writing ABSL_GUARDED_BY(mu) = false;
    bool finished ABSL_GUARDED_BY(mu) = false;
    bool final_sent ABSL_GUARDED_BY(mu) = false;
    std::optional<grpc::Status> pending_finish ABSL_GUARDED_BY(mu);

    // Sends `update` now, or keeps it for after the write in flight.
    void OfferLocked(std::shared_ptr<const pb::JobUpdate> update, bool final) ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu);
    void SendLocked(std::shared_ptr<const pb::JobUpdate> update, bool final) ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu);
    void FinishLocked(const grpc::Status& status) ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu);
  };

  explicit JobWatchReactor(std::shared_ptr<Stream> stream) : stream_(std::move(stream)) {}
  static void Subscribe(const std::shared_ptr<Stream>& stream);
  // Wakes the stream: set dirty, post a build unless one is under way.
  static void OnChange(const std::shared_ptr<Stream>& stream);
  // With `building` owned: posts the build to the pool now, or when the
  // stream's pause after its last build is over.
  static void ScheduleBuild(const std::shared_ptr<Stream>& stream);
  // On the pool: builds and offers one update, then schedules the next if
  // the job changed meanwhile.
  static void Build(const std::shared_ptr<Stream>& stream);

  const std::shared_ptr<Stream> stream_;
};

}  // namespace surfmap
