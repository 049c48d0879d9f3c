// WalCheckpointer: copies the WAL back into the database file on its own
// thread and connection, so checkpoint I/O (a write of every page plus an
// fsync of the database file) stays off the group-commit writer's commit path.
//
// It replaces SQLite's automatic checkpoint on the writer connection: a WAL
// hook on that connection wakes this thread once the WAL holds `wake_bytes`
// of frames not yet copied back; this thread then copies them with a PASSIVE
// checkpoint, which blocks neither the writer nor readers.
//
// A passive checkpoint copies only the frames present when it starts, so under
// continuous writes it never quite catches up and the WAL would never restart
// from its beginning. Hence, once the WAL holds `inline_bytes` of frames, the hook
// checkpoints on the writer thread itself, between two batches: nothing is
// appended meanwhile, it catches up fully (cheaply: the background passes
// already copied most frames) and the next write restarts the WAL. This bounds
// the WAL at about inline_bytes plus one batch.
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <thread>

#include "absl/base/thread_annotations.h"
#include "absl/status/statusor.h"
#include "server/base/mutex.h"
#include "storage/sqlite_connection.h"

namespace surfmap {

struct WalCheckpointOptions {
  int64_t wake_bytes = 4 << 20;     // SQLite's default autocheckpoint is ~4 MB
  int64_t inline_bytes = 16 << 20;  // the writer catches up itself
};

class WalCheckpointer {
 public:
  // Opens its own connection to path and installs the WAL hook on `writer_db`
  // (which must not be in use by another thread during this call, and must be
  // closed before this object is destroyed: the hook points here).
  static absl::StatusOr<std::unique_ptr<WalCheckpointer>> Start(const std::string& path,
                                                                SqliteConnection& writer_db,
                                                                WalCheckpointOptions options);
  // Runs a last checkpoint and stops the thread.
  ~WalCheckpointer();

  int64_t checkpoints() const;

 private:
  WalCheckpointer(std::unique_ptr<SqliteConnection> db, int wake_pages, int inline_pages);
  static int OnWalCommit(void* self, struct sqlite3* db, const char* name, int wal_pages);
  void Loop();

  std::unique_ptr<SqliteConnection> db_;
  const int wake_pages_;    // thresholds in WAL frames (pages) of this file
  const int inline_pages_;
  // The writer's inline catch-up (see OnWalCommit) against background passes.
  void TakeInlineTurn() ABSL_LOCKS_EXCLUDED(mu_);
  void EndInlineTurn() ABSL_LOCKS_EXCLUDED(mu_);

  mutable Mutex mu_;
  bool requested_ ABSL_GUARDED_BY(mu_) = false;
  bool stopping_ ABSL_GUARDED_BY(mu_) = false;
  bool background_pass_ ABSL_GUARDED_BY(mu_) = false;  // a checkpoint runs on this thread
  bool inline_turn_ ABSL_GUARDED_BY(mu_) = false;      // the writer checkpoints: no pass may start
  int64_t checkpoints_ ABSL_GUARDED_BY(mu_) = 0;
  // WAL frames the last checkpoint copied back; the WAL restarting from frame
  // 0 shows as a commit with fewer frames than this.
  std::atomic<int> backfilled_{0};
  std::thread thread_;
};

}  // namespace surfmap
