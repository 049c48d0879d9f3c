// kill -9 durability: a child process accepts traces and reports each
// acknowledged command id through a pipe; the parent SIGKILLs it mid-stream,
// reopens the database and checks that every acknowledged trace is there,
// intact. (Power loss cannot be simulated here; it is covered by
// synchronous=FULL, which fsyncs the WAL before a commit returns, and is
// checked in schema_test.cc.)
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <set>
#include <thread>

#include "gtest/gtest.h"
#include "storage/sqlite_store.h"
#include "storage/store_test_support_for_test.h"
#include "storage/temp_db_dir_for_test.h"

namespace surfmap {
namespace {

constexpr int kCommands = 2000;
constexpr int kSamples = 1000;
constexpr int kRigThreads = 6;
constexpr size_t kAcksPerRound = 25;
// Several kill/reopen rounds: one kill -9 lands in the window between an early
// acknowledgement and the WAL write only now and then.
constexpr int kRounds = 20;

// The child: never returns.
// Round r leases at time r * 1e7 ms with 1e6 ms leases, so the leases a killed
// child held have expired for the next round.
[[noreturn]] void RunRigsAndReportAcks(const std::string& path, int64_t job_id, int round,
                                       int ack_fd) {
  absl::StatusOr<std::unique_ptr<SqliteStore>> store = SqliteStore::Open(path);
  if (!store.ok()) _exit(10);
  std::vector<std::thread> rigs;
  for (int r = 0; r < kRigThreads; ++r) {
    rigs.emplace_back([&store, job_id, round, ack_fd, r] {
      const std::string owner = "rig-" + std::to_string(r);
      while (true) {
        absl::StatusOr<std::optional<CommandRecord>> c =
            (*store)->LeaseNextCommand(LeaseRequest{job_id, owner, round * 10'000'000LL, 1'000'000});
        if (!c.ok()) _exit(11);
        if (!c->has_value()) return;
        AcceptTraceRequest request = MakeTestAccept(**c, kSamples);
        request.new_plan_json.clear();
        absl::StatusOr<AcceptTraceResult> result = (*store)->AcceptTrace(std::move(request));
        if (!result.ok()) _exit(12);
        // Acknowledged: tell the parent (8-byte writes to a pipe are atomic).
        int64_t id = (*c)->id;
        if (write(ack_fd, &id, sizeof id) != sizeof id) _exit(13);
      }
    });
  }
  for (std::thread& t : rigs) t.join();
  _exit(0);
}

TEST(CrashDurabilityTest, EveryAcknowledgedTraceSurvivesKill9) {
  TempDbDir dir;
  const std::string path = dir.Path("crash.db");
  int64_t job_id = 0;
  {
    absl::StatusOr<std::unique_ptr<SqliteStore>> store = SqliteStore::Open(path);
    ASSERT_TRUE(store.ok()) << store.status();
    absl::StatusOr<CreatedJob> job = MakeTestJob(**store, kCommands);
    ASSERT_TRUE(job.ok()) << job.status();
    job_id = job->job.id;
  }  // store closed: no threads alive while forking

  std::set<int64_t> acked;
  for (int round = 1; round <= kRounds; ++round) {
    int fds[2];
    ASSERT_EQ(pipe(fds), 0);
    pid_t child = fork();
    ASSERT_GE(child, 0);
    if (child == 0) {
      close(fds[0]);
      RunRigsAndReportAcks(path, job_id, round, fds[1]);
    }
    close(fds[1]);
    auto read_ack = [&](int timeout_ms) {
      pollfd p{fds[0], POLLIN, 0};
      if (poll(&p, 1, timeout_ms) <= 0) return false;
      int64_t id = 0;
      ssize_t n = read(fds[0], &id, sizeof id);
      if (n != sizeof id) return false;  // EOF (child gone) or torn read
      acked.insert(id);
      return true;
    };
    const size_t target = acked.size() + kAcksPerRound;
    while (acked.size() < target && read_ack(60'000)) {
    }
    ASSERT_EQ(kill(child, SIGKILL), 0);
    int status = 0;
    ASSERT_EQ(waitpid(child, &status, 0), child);
    ASSERT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL)
        << "round " << round << ": child ended on its own before the kill (exit code "
        << (WIFEXITED(status) ? WEXITSTATUS(status) : -1) << ")";
    while (read_ack(0)) {  // acks written before the kill are acknowledged too
    }
    close(fds[0]);
    ASSERT_GE(acked.size(), target);
  }

  absl::StatusOr<std::unique_ptr<SqliteStore>> store = SqliteStore::Open(path);
  ASSERT_TRUE(store.ok()) << store.status();
  absl::StatusOr<std::vector<TraceRecord>> traces = (*store)->ListTraces(job_id, true);
  ASSERT_TRUE(traces.ok()) << traces.status();
  std::set<int64_t> stored;
  for (const TraceRecord& t : *traces) {
    stored.insert(t.command_id);
    // Every stored trace (acknowledged or not) is whole: atomic writes.
    std::vector<StoredSample> expected = MakeTestSamples(kSamples, static_cast<uint64_t>(t.command_id));
    ASSERT_EQ(t.samples.size(), expected.size()) << "trace " << t.id;
    for (size_t i = 0; i < expected.size(); ++i) {
      ASSERT_TRUE(BitwiseEqual(t.samples[i], expected[i])) << "trace " << t.id << " sample " << i;
    }
    absl::StatusOr<FitRecord> fit = (*store)->GetFit(t.id, 1);
    ASSERT_TRUE(fit.ok()) << "trace " << t.id << ": " << fit.status();
    absl::StatusOr<CommandRecord> command = (*store)->GetCommand(t.command_id);
    ASSERT_TRUE(command.ok());
    EXPECT_EQ(command->state, CommandState::kDone);
  }
  for (int64_t id : acked) EXPECT_TRUE(stored.count(id)) << "acknowledged command " << id << " lost";
  EXPECT_LT(stored.size(), static_cast<size_t>(kCommands)) << "killed too late to be mid-stream";
  std::cerr << "[ info ] acknowledged " << acked.size() << ", stored " << stored.size()
            << " of " << kCommands << " traces at the kill\n";

  auto db = SqliteConnection::Open(path, {});
  ASSERT_TRUE(db.ok());
  absl::StatusOr<SqliteStatement> check = (*db)->Prepare("PRAGMA integrity_check");
  ASSERT_TRUE(check.ok());
  ASSERT_TRUE(*check->Step());
  EXPECT_EQ(check->ColumnText(0), "ok");
}

}  // namespace
}  // namespace surfmap
