// A small pool of read-only connections to one database. In WAL mode readers
// do not block the writer nor each other, so reads never queue behind the
// group-commit writer. Each read statement sees the last committed state.
#pragma once

#include <condition_variable>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "storage/sqlite_connection.h"

namespace surfmap {

class ReadConnectionPool {
 public:
  // A connection on loan; returns to the pool when destroyed.
  class Loan {
   public:
    Loan(ReadConnectionPool* pool, std::unique_ptr<SqliteConnection> connection)
        : pool_(pool), connection_(std::move(connection)) {}
    Loan(Loan&&) = default;
    ~Loan();
    SqliteConnection& operator*() const { return *connection_; }
    SqliteConnection* operator->() const { return connection_.get(); }

   private:
    ReadConnectionPool* pool_;
    std::unique_ptr<SqliteConnection> connection_;
  };

  // Opens connections lazily, at most max_connections (>= 1) at once; a
  // borrower waits when all are on loan.
  ReadConnectionPool(std::string path, int max_connections, int busy_timeout_ms);

  // Unavailable if a new connection cannot be opened.
  absl::StatusOr<Loan> Borrow();

 private:
  void Return(std::unique_ptr<SqliteConnection> connection);

  const std::string path_;
  const int max_connections_;
  const int busy_timeout_ms_;
  std::mutex mu_;
  std::condition_variable available_;
  std::vector<std::unique_ptr<SqliteConnection>> idle_;  // guarded by mu_
  int open_ = 0;                                         // guarded by mu_
};

}  // namespace surfmap
