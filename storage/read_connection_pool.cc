#include "storage/read_connection_pool.h"

#include <algorithm>

namespace surfmap {

ReadConnectionPool::Loan::~Loan() {
  if (connection_ != nullptr) pool_->Return(std::move(connection_), size_);
}

ReadConnectionPool::ReadConnectionPool(std::string path, int max_connections, int max_bulk,
                                       int busy_timeout_ms)
    : path_(std::move(path)),
      max_connections_(std::max(2, max_connections)),
      max_bulk_(std::clamp(max_bulk, 1, std::max(2, max_connections) - 1)),
      busy_timeout_ms_(busy_timeout_ms) {}

absl::StatusOr<ReadConnectionPool::Loan> ReadConnectionPool::Borrow(ReadSize size) {
  {
    MutexLock lock(&mu_);
    const bool bulk = size == ReadSize::kBulk;
    mu_.Await([this, bulk]() ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu_) { return bulk ? CanLendBulk() : CanLend(); });
    if (size == ReadSize::kBulk) ++bulk_on_loan_;
    if (!idle_.empty()) {
      std::unique_ptr<SqliteConnection> connection = std::move(idle_.back());
      idle_.pop_back();
      return Loan(this, std::move(connection), size);
    }
    ++open_;  // reserve the slot, open outside the lock
  }
  SqliteOpenOptions options;
  options.create = false;
  options.read_only = true;
  options.busy_timeout_ms = busy_timeout_ms_;
  absl::StatusOr<std::unique_ptr<SqliteConnection>> connection = SqliteConnection::Open(path_, options);
  if (!connection.ok()) {
    MutexLock lock(&mu_);
    --open_;
    if (size == ReadSize::kBulk) --bulk_on_loan_;
    return connection.status();
  }
  return Loan(this, std::move(*connection), size);
}

void ReadConnectionPool::Return(std::unique_ptr<SqliteConnection> connection, ReadSize size) {
  MutexLock lock(&mu_);
  if (size == ReadSize::kBulk) --bulk_on_loan_;
  idle_.push_back(std::move(connection));
}

}  // namespace surfmap
