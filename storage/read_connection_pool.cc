#include "storage/read_connection_pool.h"

#include <algorithm>

namespace surfmap {

ReadConnectionPool::Loan::~Loan() {
  if (connection_ != nullptr) pool_->Return(std::move(connection_));
}

ReadConnectionPool::ReadConnectionPool(std::string path, int max_connections,
                                       int busy_timeout_ms)
    : path_(std::move(path)),
      max_connections_(std::max(1, max_connections)),
      busy_timeout_ms_(busy_timeout_ms) {}

absl::StatusOr<ReadConnectionPool::Loan> ReadConnectionPool::Borrow() {
  {
    std::unique_lock<std::mutex> lock(mu_);
    available_.wait(lock, [this] { return !idle_.empty() || open_ < max_connections_; });
    if (!idle_.empty()) {
      std::unique_ptr<SqliteConnection> connection = std::move(idle_.back());
      idle_.pop_back();
      return Loan(this, std::move(connection));
    }
    ++open_;  // reserve the slot, open outside the lock
  }
  SqliteOpenOptions options;
  options.create = false;
  options.read_only = true;
  options.busy_timeout_ms = busy_timeout_ms_;
  absl::StatusOr<std::unique_ptr<SqliteConnection>> connection =
      SqliteConnection::Open(path_, options);
  if (!connection.ok()) {
    {
      std::lock_guard<std::mutex> lock(mu_);
      --open_;
    }
    available_.notify_one();
    return connection.status();
  }
  return Loan(this, std::move(*connection));
}

void ReadConnectionPool::Return(std::unique_ptr<SqliteConnection> connection) {
  {
    std::lock_guard<std::mutex> lock(mu_);
    idle_.push_back(std::move(connection));
  }
  available_.notify_one();
}

}  // namespace surfmap
