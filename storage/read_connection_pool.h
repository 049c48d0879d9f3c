// A small pool of read-only connections to one database. In WAL mode readers
// do not block the writer nor each other, so reads never queue behind the
// group-commit writer. Each read statement sees the last committed state.
//
// Two kinds of loans: small reads (a row or an index lookup) and bulk reads
// (trace samples, a job's every sample). Bulk loans are capped below the pool
// size, so a few slow bulk reads can never take every connection: a small
// read waits at most for another small read to finish.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "absl/base/thread_annotations.h"
#include "absl/status/statusor.h"
#include "server/base/mutex.h"
#include "storage/sqlite_connection.h"

namespace surfmap {

enum class ReadSize { kSmall, kBulk };

class ReadConnectionPool {
 public:
  // A connection on loan; returns to the pool when destroyed.
  class Loan {
   public:
    Loan(ReadConnectionPool* pool, std::unique_ptr<SqliteConnection> connection, ReadSize size)
        : pool_(pool), connection_(std::move(connection)), size_(size) {}
    Loan(Loan&&) = default;
    ~Loan();
    SqliteConnection& operator*() const { return *connection_; }
    SqliteConnection* operator->() const { return connection_.get(); }

   private:
    ReadConnectionPool* pool_;
    std::unique_ptr<SqliteConnection> connection_;
    ReadSize size_;
  };

  // Opens connections lazily, at most max_connections (>= 2) at once, of which
  // at most max_connections - 1 (and at most max_bulk) on bulk loan.
  ReadConnectionPool(std::string path, int max_connections, int max_bulk, int busy_timeout_ms);

  // Waits for a free slot of the kind (never for the writer). Unavailable if
  // a new connection cannot be opened.
  absl::StatusOr<Loan> Borrow(ReadSize size = ReadSize::kSmall) ABSL_LOCKS_EXCLUDED(mu_);

 private:
  void Return(std::unique_ptr<SqliteConnection> connection, ReadSize size) ABSL_LOCKS_EXCLUDED(mu_);
  bool CanLend() const ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu_) {
    return !idle_.empty() || open_ < max_connections_;
  }
  bool CanLendBulk() const ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu_) { return bulk_on_loan_ < max_bulk_ && CanLend(); }

  const std::string path_;
  const int max_connections_;
  const int max_bulk_;
  const int busy_timeout_ms_;
  Mutex mu_;
  std::vector<std::unique_ptr<SqliteConnection>> idle_ ABSL_GUARDED_BY(mu_);
  int open_ ABSL_GUARDED_BY(mu_) = 0;
  int bulk_on_loan_ ABSL_GUARDED_BY(mu_) = 0;
};

}  // namespace surfmap
