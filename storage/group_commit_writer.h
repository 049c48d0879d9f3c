// GroupCommitWriter: the single writer of a SQLite database. One thread owns
// the write connection and runs every submitted write, committing many writes
// with one fsync (group commit).
//
// Why: with synchronous=FULL each commit costs an fsync (0.4-3 ms measured on
// the project VM, see the storage report), which caps one-commit-per-write at a
// few hundred to ~2,000 writes/s. Here the thread takes every queued write (up
// to max_batch), opens one transaction, runs each write inside its own
// SAVEPOINT (so one failing write rolls back alone and each write stays
// atomic), commits once, and only then completes each write's callback. While
// it commits, new writes queue up and form the next batch, so the batch size
// follows the load without any added delay.
//
// Guarantees: a callback receiving OK means the write is committed durably. A
// write that failed wrote nothing. If the commit itself fails, every write of
// the batch receives that error and none of them is in the database. Writes
// run in submission order and see the effects of earlier writes of the batch.
#pragma once

#include <cstdint>
#include <deque>
#include <functional>
#include <future>
#include <memory>
#include <thread>

#include "absl/base/thread_annotations.h"
#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "server/base/mutex.h"
#include "storage/sqlite_connection.h"

namespace surfmap {

struct GroupCommitOptions {
  // false: one transaction (one fsync) per write; for comparison and debugging.
  bool group_commit = true;
  int max_batch = 256;  // writes per transaction, >= 1
};

struct GroupCommitStats {
  int64_t transactions = 0;   // committed or failed
  int64_t writes = 0;         // completed writes, including failed ones
  int64_t failed_writes = 0;
  int64_t largest_batch = 0;
};

class GroupCommitWriter {
 public:
  // Runs inside a savepoint on the writer thread; returning an error rolls back
  // to the savepoint. Must not begin or end transactions itself.
  using Work = std::function<absl::Status(SqliteConnection&)>;
  // Receives the write's final status. Runs on the writer thread, after the
  // commit; must not block (in particular must not wait for another write).
  using Done = std::function<void(absl::Status)>;

  // Starts the thread. `db` must be open and migrated.
  GroupCommitWriter(std::unique_ptr<SqliteConnection> db, GroupCommitOptions options);
  // Completes every write submitted before, then stops the thread.
  ~GroupCommitWriter();
  GroupCommitWriter(const GroupCommitWriter&) = delete;
  GroupCommitWriter& operator=(const GroupCommitWriter&) = delete;

  // Queues a write. After shutdown began, `done` gets Unavailable at once.
  // Never waits: the lock it takes is held only to push onto the queue.
  void Submit(Work work, Done done) ABSL_LOCKS_EXCLUDED(mu_);

  // Typed form: `work` produces a value, `done` receives it once durable.
  template <typename T>
  void SubmitForResult(std::function<absl::StatusOr<T>(SqliteConnection&)> work,
                       std::function<void(absl::StatusOr<T>)> done) {
    auto result = std::make_shared<absl::StatusOr<T>>(absl::InternalError("write never ran"));
    Submit(
        [work = std::move(work), result](SqliteConnection& db) {
          *result = work(db);
          return result->status();
        },
        [done = std::move(done), result](absl::Status status) {
          if (!status.ok()) {
            done(std::move(status));
          } else {
            done(std::move(*result));
          }
        });
  }

  // Blocking form (not from inside a callback).
  template <typename T>
  absl::StatusOr<T> Run(std::function<absl::StatusOr<T>(SqliteConnection&)> work) {
    std::promise<absl::StatusOr<T>> promise;
    std::future<absl::StatusOr<T>> future = promise.get_future();
    SubmitForResult<T>(std::move(work),
                       [&promise](absl::StatusOr<T> r) { promise.set_value(std::move(r)); });
    return future.get();
  }

  GroupCommitStats stats() const;

 private:
  struct Pending {
    Work work;
    Done done;
    absl::Status status;
  };

  void Loop();
  bool HasWorkOrStopping() const ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu_) { return stopping_ || !queue_.empty(); }
  void RunBatch(std::deque<Pending>& batch);

  std::unique_ptr<SqliteConnection> db_;
  const GroupCommitOptions options_;

  mutable Mutex mu_;
  std::deque<Pending> queue_ ABSL_GUARDED_BY(mu_);
  bool stopping_ ABSL_GUARDED_BY(mu_) = false;
  GroupCommitStats stats_ ABSL_GUARDED_BY(mu_);

  std::thread thread_;  // last: starts after everything above is initialized
};

}  // namespace surfmap
