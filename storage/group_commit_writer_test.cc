#include "storage/group_commit_writer.h"

#include <future>
#include <vector>

#include "gtest/gtest.h"
#include "storage/temp_db_dir_for_test.h"

namespace surfmap {
namespace {

class GroupCommitWriterTest : public ::testing::TestWithParam<bool> {
 protected:
  std::unique_ptr<GroupCommitWriter> MakeWriter(bool group_commit) {
    auto db = SqliteConnection::Open(path_, {});
    EXPECT_TRUE(db.ok()) << db.status();
    EXPECT_TRUE((*db)->Exec("CREATE TABLE IF NOT EXISTS t (x INTEGER NOT NULL)").ok());
    GroupCommitOptions options;
    options.group_commit = group_commit;
    return std::make_unique<GroupCommitWriter>(std::move(*db), options);
  }

  static GroupCommitWriter::Work Insert(int x) {
    return [x](SqliteConnection& db) {
      absl::StatusOr<SqliteStatement> s = db.Prepare("INSERT INTO t (x) VALUES (?1)");
      if (!s.ok()) return s.status();
      s->BindInt(1, x);
      return s->Run();
    };
  }

  std::vector<int64_t> Rows() {
    auto db = SqliteConnection::Open(path_, {});
    absl::StatusOr<SqliteStatement> s = (*db)->Prepare("SELECT x FROM t ORDER BY x");
    std::vector<int64_t> rows;
    while (*s->Step()) rows.push_back(s->ColumnInt(0));
    return rows;
  }

  TempDbDir dir_;
  std::string path_ = dir_.Path("w.db");
};

// Holds the writer inside its first write until `release` is set, so that
// every write submitted meanwhile is queued and forms the next batch.
struct Gate {
  std::promise<void> entered;
  std::promise<void> release;
};

TEST_P(GroupCommitWriterTest, QueuedWritesShareOneTransactionOnlyWithGroupCommit) {
  const bool group_commit = GetParam();
  auto writer = MakeWriter(group_commit);
  Gate gate;
  std::shared_future<void> release = gate.release.get_future().share();
  std::promise<absl::Status> first_done;
  writer->Submit(
      [&gate, release](SqliteConnection& db) {
        gate.entered.set_value();
        release.wait();
        return absl::OkStatus();
      },
      [&first_done](absl::Status s) { first_done.set_value(s); });
  gate.entered.get_future().wait();

  constexpr int kQueued = 20;
  std::vector<std::promise<absl::Status>> done(kQueued);
  for (int i = 0; i < kQueued; ++i) {
    writer->Submit(Insert(i), [&done, i](absl::Status s) { done[i].set_value(s); });
  }
  gate.release.set_value();
  EXPECT_TRUE(first_done.get_future().get().ok());
  for (auto& d : done) EXPECT_TRUE(d.get_future().get().ok());

  GroupCommitStats stats = writer->stats();
  EXPECT_EQ(stats.writes, kQueued + 1);
  if (group_commit) {
    EXPECT_EQ(stats.transactions, 2);
    EXPECT_EQ(stats.largest_batch, kQueued);
  } else {
    EXPECT_EQ(stats.transactions, kQueued + 1);
    EXPECT_EQ(stats.largest_batch, 1);
  }
  EXPECT_EQ(Rows().size(), static_cast<size_t>(kQueued));
}

TEST_P(GroupCommitWriterTest, FailingWriteRollsBackAloneInsideItsBatch) {
  auto writer = MakeWriter(GetParam());
  Gate gate;
  std::shared_future<void> release = gate.release.get_future().share();
  writer->Submit(
      [&gate, release](SqliteConnection&) {
        gate.entered.set_value();
        release.wait();
        return absl::OkStatus();
      },
      [](absl::Status) {});
  gate.entered.get_future().wait();

  std::promise<absl::Status> a, b, c;
  writer->Submit(Insert(1), [&a](absl::Status s) { a.set_value(s); });
  // Writes 2, then fails: its row must vanish, the batch must not.
  writer->Submit(
      [](SqliteConnection& db) {
        if (absl::Status s = Insert(2)(db); !s.ok()) return s;
        return absl::InvalidArgumentError("request 2 is bad");
      },
      [&b](absl::Status s) { b.set_value(s); });
  // Sees the batch's earlier, not yet committed, write.
  std::promise<int64_t> seen;
  writer->Submit(
      [&seen](SqliteConnection& db) {
        absl::StatusOr<int64_t> n = db.QueryInt("SELECT COUNT(*) FROM t");
        seen.set_value(n.ok() ? *n : -1);
        return Insert(3)(db);
      },
      [&c](absl::Status s) { c.set_value(s); });
  gate.release.set_value();

  EXPECT_TRUE(a.get_future().get().ok());
  absl::Status bs = b.get_future().get();
  EXPECT_EQ(bs.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(bs.message(), "request 2 is bad");
  EXPECT_TRUE(c.get_future().get().ok());
  EXPECT_EQ(seen.get_future().get(), 1);
  EXPECT_EQ(Rows(), (std::vector<int64_t>{1, 3}));
  EXPECT_EQ(writer->stats().failed_writes, 1);
}

TEST_P(GroupCommitWriterTest, ConstraintErrorInOneWriteKeepsOthers) {
  auto writer = MakeWriter(GetParam());
  std::vector<std::future<absl::StatusOr<int>>> results;
  for (int i = 0; i < 50; ++i) {
    auto promise = std::make_shared<std::promise<absl::StatusOr<int>>>();
    results.push_back(promise->get_future());
    writer->SubmitForResult<int>(
        [i](SqliteConnection& db) -> absl::StatusOr<int> {
          absl::StatusOr<SqliteStatement> s = db.Prepare("INSERT INTO t (x) VALUES (?1)");
          if (!s.ok()) return s.status();
          if (i % 10 == 3) {
            s->BindNull(1);  // NOT NULL violation
          } else {
            s->BindInt(1, i);
          }
          if (absl::Status st = s->Run(); !st.ok()) return st;
          return i * 2;
        },
        [promise](absl::StatusOr<int> r) { promise->set_value(std::move(r)); });
  }
  int ok = 0;
  for (int i = 0; i < 50; ++i) {
    absl::StatusOr<int> r = results[i].get();
    if (i % 10 == 3) {
      EXPECT_EQ(r.status().code(), absl::StatusCode::kInvalidArgument) << r.status();
    } else {
      ASSERT_TRUE(r.ok()) << r.status();
      EXPECT_EQ(*r, 2 * i);
      ++ok;
    }
  }
  EXPECT_EQ(Rows().size(), static_cast<size_t>(ok));
}

TEST_P(GroupCommitWriterTest, DestructionCompletesQueuedWrites) {
  std::vector<std::promise<absl::Status>> done(30);
  {
    auto writer = MakeWriter(GetParam());
    for (int i = 0; i < 30; ++i) {
      writer->Submit(Insert(i), [&done, i](absl::Status s) { done[i].set_value(s); });
    }
  }
  for (auto& d : done) EXPECT_TRUE(d.get_future().get().ok());
  EXPECT_EQ(Rows().size(), 30u);
}

INSTANTIATE_TEST_SUITE_P(GroupCommitOnOff, GroupCommitWriterTest, ::testing::Bool(),
                         [](const ::testing::TestParamInfo<bool>& info) {
                           return info.param ? "GroupCommit" : "CommitPerWrite";
                         });

}  // namespace
}  // namespace surfmap
