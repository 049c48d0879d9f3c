#include "storage/group_commit_writer.h"

#include <sqlite3.h>

#include <algorithm>

#include "absl/strings/str_cat.h"

namespace surfmap {

GroupCommitWriter::GroupCommitWriter(std::unique_ptr<SqliteConnection> db,
                                     GroupCommitOptions options)
    : db_(std::move(db)), options_(options), thread_([this] { Loop(); }) {}

GroupCommitWriter::~GroupCommitWriter() {
  {
    MutexLock lock(&mu_);
    stopping_ = true;
  }
  thread_.join();
}

void GroupCommitWriter::Submit(Work work, Done done) {
  {
    MutexLock lock(&mu_);
    if (!stopping_) {
      queue_.push_back(Pending{std::move(work), std::move(done), absl::OkStatus()});
      return;
    }
  }
  done(absl::UnavailableError("store is shutting down: write not accepted"));
}

GroupCommitStats GroupCommitWriter::stats() const {
  MutexLock lock(&mu_);
  return stats_;
}

void GroupCommitWriter::Loop() {
  const size_t max_batch =
      options_.group_commit ? static_cast<size_t>(std::max(1, options_.max_batch)) : 1;
  while (true) {
    std::deque<Pending> batch;
    {
      MutexLock lock(&mu_);
      mu_.Await([this]() ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu_) { return HasWorkOrStopping(); });
      if (queue_.empty()) return;  // stopping and drained
      while (!queue_.empty() && batch.size() < max_batch) {
        batch.push_back(std::move(queue_.front()));
        queue_.pop_front();
      }
    }
    RunBatch(batch);
    int64_t failed = 0;
    for (const Pending& p : batch) failed += p.status.ok() ? 0 : 1;
    {
      MutexLock lock(&mu_);
      stats_.transactions += 1;
      stats_.writes += static_cast<int64_t>(batch.size());
      stats_.failed_writes += failed;
      stats_.largest_batch = std::max<int64_t>(stats_.largest_batch, batch.size());
    }
    // Only now, after the commit, does anyone learn the outcome.
    for (Pending& p : batch) p.done(std::move(p.status));
  }
}

void GroupCommitWriter::RunBatch(std::deque<Pending>& batch) {
  auto fail_all = [&batch](const absl::Status& status) {
    for (Pending& p : batch) p.status = status;
  };
  if (absl::Status s = db_->Exec("BEGIN IMMEDIATE"); !s.ok()) {
    fail_all(s);
    return;
  }
  for (Pending& p : batch) {
    absl::Status s = db_->Exec("SAVEPOINT write");
    if (s.ok()) {
      p.status = p.work(*db_);
      if (sqlite3_get_autocommit(db_->handle())) {
        // SQLite rolled back the whole transaction itself (I/O error, disk
        // full, out of memory): every write of the batch so far is gone.
        fail_all(absl::UnavailableError(absl::StrCat(
            "transaction rolled back by SQLite; write error: ", p.status.ToString())));
        return;
      }
      s = p.status.ok() ? db_->Exec("RELEASE write")
                        : db_->Exec("ROLLBACK TO write; RELEASE write");
    }
    if (!s.ok()) {  // the savepoint machinery itself failed: give up the batch
      db_->Exec("ROLLBACK").IgnoreError();
      fail_all(s);
      return;
    }
  }
  if (absl::Status s = db_->Exec("COMMIT"); !s.ok()) {
    db_->Exec("ROLLBACK").IgnoreError();
    absl::Status commit_error(s.code(), absl::StrCat("commit failed, write not stored: ",
                                                     s.message()));
    for (Pending& p : batch) {
      if (p.status.ok()) p.status = commit_error;
    }
  }
}

}  // namespace surfmap
