// How many commands a job keeps issued ahead of its answers.
//
// The plan decides each drag from the map as it stands when the command is
// issued: a coarse site that an earlier drag already covered is skipped, and
// a boundary drag is aimed with the latest map. A command issued long before
// a rig takes it was decided on an old map. So the service issues only as
// many commands as there are rigs to take them (a job's commands are issued
// again after every answer), not the whole plan at once: enough that no rig
// waits for the plan, few enough that every drag uses what the drags before
// it found.
//
// Rigs are counted by who asked the service for a command recently (a lease,
// a trace or a failure report, for any job): each for the lease time of the
// job it asked about, since a rig busy with a drag holds its lease at most
// that long before it asks again. At least one command is always issued
// ahead, so a job with work left always has a command for the next rig; a
// rig that joins finds one after the next answer (or at once when it is the
// second rig and the first holds none).
//
// Thread-safe; its lock is a leaf (held only for the map below).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <unordered_map>

#include "absl/base/thread_annotations.h"
#include "server/base/mutex.h"

namespace surfmap {

class CommandLookahead {
 public:
  // At most this many rigs are counted at once: rig ids come from clients, so
  // a client inventing ids must not grow the map without bound (and issuing
  // more than this many commands ahead has no use).
  static constexpr std::size_t kMaxCountedRigs = 4096;

  // A rig asked for a command (or answered one) about a job whose leases last
  // `lease_ms`: it counts until now + lease_ms (the later, if it already did).
  void RigAsked(const std::string& rig_id, int64_t now_unix_ms, int64_t lease_ms) ABSL_LOCKS_EXCLUDED(mu_);

  // Commands a job should keep issued and unanswered now: the rigs still
  // counted, at least 1.
  int CommandsAhead(int64_t now_unix_ms) ABSL_LOCKS_EXCLUDED(mu_);

 private:
  void ForgetQuietRigsLocked(int64_t now_unix_ms) ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu_);

  Mutex mu_;
  std::unordered_map<std::string, int64_t> counted_until_ms_ ABSL_GUARDED_BY(mu_);
};

}  // namespace surfmap
