#include "storage/wal_checkpointer.h"

#include <sqlite3.h>

#include <algorithm>

namespace surfmap {

absl::StatusOr<std::unique_ptr<WalCheckpointer>> WalCheckpointer::Start(
    const std::string& path, SqliteConnection& writer_db, WalCheckpointOptions options) {
  SqliteOpenOptions open_options;
  open_options.create = false;
  absl::StatusOr<std::unique_ptr<SqliteConnection>> db = SqliteConnection::Open(path, open_options);
  if (!db.ok()) return db.status();
  absl::StatusOr<int64_t> page_size = (*db)->QueryInt("PRAGMA page_size");
  if (!page_size.ok()) return page_size.status();
  auto pages = [&](int64_t bytes) {
    return static_cast<int>(std::max<int64_t>(1, bytes / std::max<int64_t>(1, *page_size)));
  };
  std::unique_ptr<WalCheckpointer> checkpointer(new WalCheckpointer(
      std::move(*db), pages(options.wake_bytes), pages(options.inline_bytes)));
  // Replaces the writer's autocheckpoint (which is itself a WAL hook).
  sqlite3_wal_hook(writer_db.handle(), &WalCheckpointer::OnWalCommit, checkpointer.get());
  return checkpointer;
}

WalCheckpointer::WalCheckpointer(std::unique_ptr<SqliteConnection> db, int wake_pages,
                                 int inline_pages)
    : db_(std::move(db)),
      wake_pages_(wake_pages),
      inline_pages_(inline_pages),
      thread_([this] { Loop(); }) {}

WalCheckpointer::~WalCheckpointer() {
  {
    MutexLock lock(&mu_);
    stopping_ = true;
  }
  thread_.join();
}

int64_t WalCheckpointer::checkpoints() const {
  MutexLock lock(&mu_);
  return checkpoints_;
}

int WalCheckpointer::OnWalCommit(void* self, sqlite3* db, const char* name, int wal_pages) {
  auto* checkpointer = static_cast<WalCheckpointer*>(self);
  if (wal_pages >= checkpointer->inline_pages_) {
    // Catch up fully on the writer thread (see the header). A pass of the
    // background thread under way holds SQLite's checkpoint lock, and a
    // passive checkpoint would then give up at once (SQLITE_BUSY): on a loaded
    // machine the WAL grew past the bound that way. So the writer takes its
    // turn: no new background pass starts, the one under way is waited for
    // (it is already copying frames), then the writer catches up itself.
    checkpointer->TakeInlineTurn();
    // Errors are ignored: returning one would report a failed commit
    // although the commit succeeded, and the next commit retries.
    sqlite3_wal_checkpoint_v2(db, name, SQLITE_CHECKPOINT_PASSIVE, nullptr, nullptr);
    checkpointer->EndInlineTurn();
    return SQLITE_OK;
  }
  int backfilled = checkpointer->backfilled_.load(std::memory_order_relaxed);
  if (wal_pages < backfilled) backfilled = 0;  // the WAL restarted
  if (wal_pages - backfilled >= checkpointer->wake_pages_) {
    MutexLock lock(&checkpointer->mu_);
    checkpointer->requested_ = true;
  }
  return SQLITE_OK;
}

void WalCheckpointer::TakeInlineTurn() {
  MutexLock lock(&mu_);
  inline_turn_ = true;
  mu_.Await([this]() ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu_) { return !background_pass_; });
}

void WalCheckpointer::EndInlineTurn() {
  MutexLock lock(&mu_);
  inline_turn_ = false;
}

void WalCheckpointer::Loop() {
  while (true) {
    {
      MutexLock lock(&mu_);
      mu_.Await([this]() ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu_) {
        return stopping_ || (requested_ && !inline_turn_);
      });
      requested_ = false;  // when stopping: one last pass, then return
      background_pass_ = true;
    }
    // Failures (e.g. busy) are harmless: the next request retries, and the
    // inline fallback bounds the WAL.
    int wal_frames = 0;
    int copied = 0;
    if (sqlite3_wal_checkpoint_v2(db_->handle(), nullptr, SQLITE_CHECKPOINT_PASSIVE, &wal_frames,
                                  &copied) == SQLITE_OK) {
      backfilled_.store(copied, std::memory_order_relaxed);
    }
    MutexLock lock(&mu_);
    background_pass_ = false;
    ++checkpoints_;
    if (stopping_) return;
  }
}

}  // namespace surfmap
