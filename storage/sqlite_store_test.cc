#include "storage/sqlite_store.h"

#include <algorithm>
#include <cmath>
#include <future>
#include <atomic>
#include <chrono>
#include <filesystem>
#include <map>
#include <set>
#include <thread>

#include "absl/strings/str_cat.h"
#include "gtest/gtest.h"
#include "storage/store_test_support_for_test.h"
#include "storage/temp_db_dir_for_test.h"

namespace surfmap {
namespace {

constexpr int64_t kStartMs = 1'700'000'000'000;

class SqliteStoreTest : public ::testing::Test {
 protected:
  void SetUp() override { Reopen(); }

  void Reopen(SqliteStoreOptions options = {}) {
    store_.reset();
    options.clock = [this] { return now_ms_.load(); };
    absl::StatusOr<std::unique_ptr<SqliteStore>> store = SqliteStore::Open(path_, options);
    ASSERT_TRUE(store.ok()) << store.status();
    store_ = std::move(*store);
  }

  CreatedJob Job(int n_commands) {
    absl::StatusOr<CreatedJob> job = MakeTestJob(*store_, n_commands);
    EXPECT_TRUE(job.ok()) << job.status();
    return job.ok() ? *job : CreatedJob{};
  }

  CommandRecord Lease(int64_t job_id, const std::string& owner, int64_t now = kStartMs,
                      int64_t duration = 60'000) {
    absl::StatusOr<std::optional<CommandRecord>> c =
        store_->LeaseNextCommand(LeaseRequest{job_id, owner, now, duration});
    EXPECT_TRUE(c.ok()) << c.status();
    EXPECT_TRUE(c.ok() && c->has_value()) << "no command to lease";
    return (c.ok() && c->has_value()) ? **c : CommandRecord{};
  }

  // Rows per table, read through a separate connection.
  std::map<std::string, int64_t> TableCounts() {
    auto db = SqliteConnection::Open(path_, {});
    EXPECT_TRUE(db.ok());
    std::map<std::string, int64_t> counts;
    for (const char* t : {"objects", "jobs", "plans", "plan_journal", "commands", "traces", "fits", "events"}) {
      counts[t] = *(*db)->QueryInt(std::string("SELECT COUNT(*) FROM ") + t);
    }
    counts["plan_revision_sum"] = *(*db)->QueryInt("SELECT TOTAL(revision) FROM plans");
    counts["leased"] = *(*db)->QueryInt("SELECT COUNT(*) FROM commands WHERE state = 'leased'");
    counts["job_states"] = *(*db)->QueryInt("SELECT COUNT(*) FROM jobs WHERE state = 'running'");
    return counts;
  }

  TempDbDir dir_;
  std::string path_ = dir_.Path("surfmap.db");
  std::atomic<int64_t> now_ms_{kStartMs};
  std::unique_ptr<SqliteStore> store_;
};

TEST_F(SqliteStoreTest, ObjectsRoundTripIncludingBinaryMesh) {
  std::string bytes("ply\0\x01\xff binary", 16);
  absl::StatusOr<int64_t> id = store_->CreateObject(NewObject{"cup", "ply", bytes, 8, 12});
  ASSERT_TRUE(id.ok()) << id.status();
  absl::StatusOr<ObjectRecord> got = store_->GetObject(*id, true);
  ASSERT_TRUE(got.ok()) << got.status();
  EXPECT_EQ(got->name, "cup");
  EXPECT_EQ(got->mesh_format, "ply");
  EXPECT_EQ(got->mesh_bytes, bytes);
  EXPECT_EQ(got->control_vertices, 8);
  EXPECT_EQ(got->control_faces, 12);
  EXPECT_EQ(got->created_unix_ms, kStartMs);
  absl::StatusOr<std::vector<ObjectRecord>> all = store_->ListObjects();
  ASSERT_TRUE(all.ok());
  ASSERT_EQ(all->size(), 1u);
  EXPECT_TRUE((*all)[0].mesh_bytes.empty());  // listing leaves the mesh out
}

TEST_F(SqliteStoreTest, InvalidInputsAndUnknownIdsGiveNamedErrors) {
  absl::StatusOr<int64_t> bad = store_->CreateObject(NewObject{"x", "stl", "abc", 0, 0});
  EXPECT_EQ(bad.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(bad.status().message().find("stl"), std::string::npos);

  absl::StatusOr<ObjectRecord> missing = store_->GetObject(77, false);
  EXPECT_EQ(missing.status().code(), absl::StatusCode::kNotFound);
  EXPECT_NE(missing.status().message().find("object 77"), std::string::npos);

  NewJob job;
  job.object_id = 5;
  job.plan_json = "{}";
  absl::StatusOr<CreatedJob> created = store_->CreateJob(job);
  EXPECT_EQ(created.status().code(), absl::StatusCode::kNotFound);
  EXPECT_NE(created.status().message().find("object 5"), std::string::npos);

  EXPECT_EQ(store_->GetJob(9).status().code(), absl::StatusCode::kNotFound);
  EXPECT_EQ(store_->GetPlan(9).status().code(), absl::StatusCode::kNotFound);
  EXPECT_EQ(store_->GetCommand(9).status().code(), absl::StatusCode::kNotFound);
  EXPECT_EQ(store_->GetTrace(9, true).status().code(), absl::StatusCode::kNotFound);
  EXPECT_EQ(store_->GetFit(9, 0).status().code(), absl::StatusCode::kNotFound);
  EXPECT_EQ(store_->ListCommands(9).status().code(), absl::StatusCode::kNotFound);
  EXPECT_EQ(store_->ListTraces(9, false).status().code(), absl::StatusCode::kNotFound);
}

TEST_F(SqliteStoreTest, CreateJobWritesJobPlanCommandsAndEventTogether) {
  CreatedJob created = Job(3);
  ASSERT_EQ(created.command_ids.size(), 3u);
  absl::StatusOr<JobRecord> job = store_->GetJob(created.job.id);
  ASSERT_TRUE(job.ok());
  EXPECT_EQ(job->state, JobState::kRunning);
  EXPECT_EQ(job->params_json, R"({"threshold":0.1})");
  absl::StatusOr<PlanRecord> plan = store_->GetPlan(created.job.id);
  ASSERT_TRUE(plan.ok());
  EXPECT_EQ(plan->revision, 1);
  absl::StatusOr<std::vector<CommandRecord>> commands = store_->ListCommands(created.job.id);
  ASSERT_TRUE(commands.ok());
  ASSERT_EQ(commands->size(), 3u);
  for (int i = 0; i < 3; ++i) {
    EXPECT_EQ((*commands)[i].id, created.command_ids[i]);
    EXPECT_EQ((*commands)[i].site_vertex, i);
    EXPECT_EQ((*commands)[i].state, CommandState::kPending);
    EXPECT_EQ((*commands)[i].attempt, 0);
  }
  absl::StatusOr<std::vector<EventRecord>> events = store_->ListEvents(created.job.id, 0, 100);
  ASSERT_TRUE(events.ok());
  ASSERT_EQ(events->size(), 1u);
  EXPECT_EQ((*events)[0].kind, "job_created");
}

TEST_F(SqliteStoreTest, CreateJobWithBadCommandJsonWritesNothing) {
  absl::StatusOr<int64_t> object = store_->CreateObject(NewObject{"o", "obj", "v", 0, 0});
  ASSERT_TRUE(object.ok());
  auto before = TableCounts();
  NewJob job;
  job.object_id = *object;
  job.plan_json = "{}";
  job.commands = {MakeTestCommand(0, 0), NewCommand{0, 1, "{oops"}};
  absl::StatusOr<CreatedJob> created = store_->CreateJob(job);
  ASSERT_FALSE(created.ok());
  EXPECT_EQ(created.status().code(), absl::StatusCode::kInvalidArgument) << created.status();
  EXPECT_NE(created.status().message().find("commands[1]"), std::string::npos) << created.status();
  EXPECT_EQ(TableCounts(), before);
}

TEST_F(SqliteStoreTest, AcceptTraceStoresEverythingAndSamplesBitExactly) {
  CreatedJob job = Job(2);
  CommandRecord command = Lease(job.job.id, "rig-a");
  EXPECT_EQ(command.id, job.command_ids[0]);
  EXPECT_EQ(command.state, CommandState::kLeased);
  EXPECT_EQ(command.attempt, 1);

  AcceptTraceRequest request = MakeTestAccept(command, 1000);
  request.samples[3].fx = -0.0;
  request.samples[4].fy = std::numeric_limits<double>::denorm_min();
  request.expected_plan_revision = 1;
  request.new_commands = {MakeTestCommand(1, 7)};
  const std::vector<StoredSample> sent = request.samples;
  now_ms_ = kStartMs + 500;
  absl::StatusOr<AcceptTraceResult> result = store_->AcceptTrace(request);
  ASSERT_TRUE(result.ok()) << result.status();
  EXPECT_FALSE(result->already_accepted);
  EXPECT_GT(result->trace_id, 0);
  EXPECT_GT(result->fit_id, 0);
  EXPECT_EQ(result->plan_revision, 2);
  ASSERT_EQ(result->new_command_ids.size(), 1u);

  absl::StatusOr<TraceRecord> trace = store_->GetTrace(result->trace_id, true);
  ASSERT_TRUE(trace.ok()) << trace.status();
  EXPECT_EQ(trace->command_id, command.id);
  EXPECT_EQ(trace->n_samples, 1000);
  EXPECT_EQ(trace->received_unix_ms, kStartMs + 500);
  ASSERT_EQ(trace->samples.size(), sent.size());
  for (size_t i = 0; i < sent.size(); ++i) {
    ASSERT_TRUE(BitwiseEqual(trace->samples[i], sent[i])) << "sample " << i;
  }
  absl::StatusOr<FitRecord> fit = store_->GetFit(result->trace_id, 0);
  ASSERT_TRUE(fit.ok());
  EXPECT_EQ(fit->id, result->fit_id);
  EXPECT_EQ(fit->version, 1);
  EXPECT_EQ(fit->estimator_name, "differential+ar2");
  EXPECT_EQ(fit->options_json, R"({"window":0.8})");
  ASSERT_TRUE(fit->mu.has_value());
  EXPECT_DOUBLE_EQ(*fit->mu, 0.1 + 0.001 * command.id);
  EXPECT_EQ(store_->GetCommand(command.id)->state, CommandState::kDone);
  EXPECT_EQ(store_->GetPlan(job.job.id)->plan_json, request.new_plan_json);
  EXPECT_EQ(store_->GetCommand(result->new_command_ids[0])->site_level, 1);
  absl::StatusOr<std::vector<TraceRecord>> traces = store_->ListTraces(job.job.id, false);
  ASSERT_TRUE(traces.ok());
  ASSERT_EQ(traces->size(), 1u);
  EXPECT_TRUE((*traces)[0].samples.empty());
  absl::StatusOr<std::vector<EventRecord>> events = store_->ListEvents(job.job.id, 0, 10);
  ASSERT_EQ(events->size(), 2u);
  EXPECT_EQ((*events)[1].kind, "trace_accepted");
}

// The plan as checkpoint + journal: entries append, a checkpoint replaces
// both, and a stale expected revision writes nothing.
TEST_F(SqliteStoreTest, PlanJournalAppendsAndACheckpointClearsIt) {
  CreatedJob job = Job(6);
  auto accept_with_entry = [&](const std::string& entry, int64_t expected) {
    AcceptTraceRequest request = MakeTestAccept(Lease(job.job.id, "rig-a"), 20);
    request.new_plan_json.clear();
    request.plan_journal_entry = entry;
    request.expected_plan_revision = expected;
    return store_->AcceptTrace(request);
  };
  absl::StatusOr<AcceptTraceResult> first = accept_with_entry(R"({"op":"fit","n":1})", 1);
  ASSERT_TRUE(first.ok()) << first.status();
  EXPECT_EQ(first->plan_revision, 2);
  absl::StatusOr<AcceptTraceResult> second = accept_with_entry(R"({"op":"fit","n":2})", 2);
  ASSERT_TRUE(second.ok()) << second.status();
  EXPECT_EQ(second->plan_revision, 3);
  absl::StatusOr<PlanRecord> plan = store_->GetPlan(job.job.id);
  ASSERT_TRUE(plan.ok()) << plan.status();
  EXPECT_EQ(plan->plan_json, R"({"measured":[]})");
  EXPECT_EQ(plan->journal, (std::vector<std::string>{R"({"op":"fit","n":1})", R"({"op":"fit","n":2})"}));
  EXPECT_EQ(plan->revision, 3);

  // A write based on an older revision loses the race: nothing is stored.
  auto before = TableCounts();
  absl::StatusOr<AcceptTraceResult> stale = accept_with_entry(R"({"op":"fit","n":3})", 2);
  EXPECT_EQ(stale.status().code(), absl::StatusCode::kAborted) << stale.status();
  before["leased"] += 1;  // the lease the helper took before the failed write
  EXPECT_EQ(TableCounts(), before);

  // A checkpoint replaces the plan and clears the journal.
  AcceptTraceRequest checkpoint = MakeTestAccept(Lease(job.job.id, "rig-b"), 20);
  checkpoint.expected_plan_revision = 3;
  absl::StatusOr<AcceptTraceResult> checkpointed = store_->AcceptTrace(checkpoint);
  ASSERT_TRUE(checkpointed.ok()) << checkpointed.status();
  EXPECT_EQ(checkpointed->plan_revision, 4);
  plan = store_->GetPlan(job.job.id);
  ASSERT_TRUE(plan.ok()) << plan.status();
  EXPECT_EQ(plan->plan_json, checkpoint.new_plan_json);
  EXPECT_TRUE(plan->journal.empty());
  EXPECT_EQ(plan->revision, 4);

  // Entries after the checkpoint continue its revisions.
  CommandRecord failing = Lease(job.job.id, "rig-c");
  FailCommandRequest fail;
  fail.command_id = failing.id;
  fail.job_id = failing.job_id;
  fail.lease_owner = "rig-c";
  fail.reason = "slipped";
  fail.plan_journal_entry = R"({"op":"failure"})";
  fail.expected_plan_revision = 4;
  std::promise<absl::StatusOr<FailCommandResult>> failed;
  store_->FailCommandAsync(fail, [&](absl::StatusOr<FailCommandResult> r) { failed.set_value(std::move(r)); });
  absl::StatusOr<FailCommandResult> fail_result = failed.get_future().get();
  ASSERT_TRUE(fail_result.ok()) << fail_result.status();
  EXPECT_EQ(fail_result->plan_revision, 5);
  plan = store_->GetPlan(job.job.id);
  EXPECT_EQ(plan->journal, std::vector<std::string>{R"({"op":"failure"})"});
  EXPECT_EQ(plan->revision, 5);
}

// What a write answers is what a later read gives, field for field, also for
// a NaN headline number (stored as empty).
void ExpectSameFit(const FitRecord& written, const FitRecord& read) {
  EXPECT_EQ(written.id, read.id);
  EXPECT_EQ(written.trace_id, read.trace_id);
  EXPECT_EQ(written.version, read.version);
  EXPECT_EQ(written.estimator_name, read.estimator_name);
  EXPECT_EQ(written.estimator_version, read.estimator_version);
  EXPECT_EQ(written.options_json, read.options_json);
  EXPECT_EQ(written.result_json, read.result_json);
  EXPECT_EQ(written.mu, read.mu);
  EXPECT_EQ(written.a1, read.a1);
  EXPECT_EQ(written.a2, read.a2);
  EXPECT_EQ(written.sigma, read.sigma);
  EXPECT_EQ(written.created_unix_ms, read.created_unix_ms);
}

TEST_F(SqliteStoreTest, WritesAnswerTheFitAsAReadGivesIt) {
  CreatedJob job = Job(1);
  CommandRecord command = Lease(job.job.id, "rig-a");
  AcceptTraceRequest request = MakeTestAccept(command, 10);
  request.fit->a2 = std::nan("");
  absl::StatusOr<AcceptTraceResult> accepted = store_->AcceptTrace(request);
  ASSERT_TRUE(accepted.ok()) << accepted.status();
  ASSERT_TRUE(accepted->fit.has_value());
  EXPECT_FALSE(accepted->fit->a2.has_value()) << "NaN is stored as empty";
  absl::StatusOr<FitRecord> first = store_->GetFit(accepted->trace_id, 1);
  ASSERT_TRUE(first.ok()) << first.status();
  ExpectSameFit(*accepted->fit, *first);

  NewFit refit = MakeTestFit(0.2);
  refit.sigma = std::nan("");
  absl::StatusOr<std::vector<FitRecord>> added = store_->AddFits({TraceRefit{accepted->trace_id, refit}});
  ASSERT_TRUE(added.ok()) << added.status();
  ASSERT_EQ(added->size(), 1u);
  absl::StatusOr<FitRecord> second = store_->GetFit(accepted->trace_id, 2);
  ASSERT_TRUE(second.ok()) << second.status();
  ExpectSameFit((*added)[0], *second);
}

TEST_F(SqliteStoreTest, JobActivityIsTheNewestTraceAndTheNewestEventTime) {
  CreatedJob job = Job(3);
  absl::StatusOr<JobActivity> empty = store_->GetJobActivity(job.job.id);
  ASSERT_TRUE(empty.ok()) << empty.status();
  EXPECT_FALSE(empty->latest_trace.has_value());
  ASSERT_TRUE(empty->last_event_unix_ms.has_value()) << "job_created is an event";
  EXPECT_EQ(*empty->last_event_unix_ms, kStartMs);

  CommandRecord a = Lease(job.job.id, "rig-a");
  CommandRecord b = Lease(job.job.id, "rig-b");
  now_ms_ = kStartMs + 100;
  absl::StatusOr<AcceptTraceResult> first = store_->AcceptTrace(MakeTestAccept(a, 10));
  ASSERT_TRUE(first.ok()) << first.status();
  now_ms_ = kStartMs + 200;
  AcceptTraceRequest second_request = MakeTestAccept(b, 10);
  second_request.events.push_back(NewEvent{"trace_accepted", "{}"});
  absl::StatusOr<AcceptTraceResult> second = store_->AcceptTrace(second_request);
  ASSERT_TRUE(second.ok()) << second.status();

  absl::StatusOr<JobActivity> activity = store_->GetJobActivity(job.job.id);
  ASSERT_TRUE(activity.ok()) << activity.status();
  ASSERT_TRUE(activity->latest_trace.has_value());
  EXPECT_EQ(activity->latest_trace->id, second->trace_id);
  EXPECT_EQ(activity->latest_trace->command_id, b.id);
  EXPECT_EQ(activity->latest_trace->received_unix_ms, kStartMs + 200);
  EXPECT_TRUE(activity->latest_trace->samples.empty()) << "read without its samples";
  EXPECT_EQ(activity->last_event_unix_ms, kStartMs + 200);
  EXPECT_EQ(store_->GetJobActivity(job.job.id + 7).status().code(), absl::StatusCode::kNotFound);
}

TEST_F(SqliteStoreTest, CountLeasedCommandsCountsOnlyUnexpiredLeases) {
  CreatedJob job = Job(5);
  EXPECT_EQ(store_->CountLeasedCommands(job.job.id, now_ms_)->total, 0);
  EXPECT_TRUE(store_->CountLeasedCommands(job.job.id, now_ms_)->by_level.empty());
  CommandRecord a = Lease(job.job.id, "rig-a", now_ms_, 1000);
  Lease(job.job.id, "rig-b", now_ms_, 5000);
  EXPECT_EQ(store_->CountLeasedCommands(job.job.id, now_ms_)->total, 2);
  // a's lease runs out at +1000 ms: from then on it counts no more.
  EXPECT_EQ(store_->CountLeasedCommands(job.job.id, now_ms_ + 999)->total, 2);
  EXPECT_EQ(store_->CountLeasedCommands(job.job.id, now_ms_ + 1000)->total, 1);
  // An answered command is done, not leased.
  ASSERT_TRUE(store_->AcceptTrace(MakeTestAccept(a, 10)).ok());
  EXPECT_EQ(store_->CountLeasedCommands(job.job.id, now_ms_)->total, 1);
  EXPECT_EQ(store_->CountLeasedCommands(job.job.id + 7, now_ms_).status().code(), absl::StatusCode::kNotFound);
}

TEST_F(SqliteStoreTest, CountLeasedCommandsSplitsThemBySiteLevel) {
  absl::StatusOr<CreatedJob> job = MakeTestJob(
      *store_, {MakeTestCommand(0, 1), MakeTestCommand(0, 2), MakeTestCommand(1, 7), MakeTestCommand(2, 9)});
  ASSERT_TRUE(job.ok()) << job.status();
  for (const char* rig : {"rig-a", "rig-b", "rig-c"}) Lease(job->job.id, rig, now_ms_, 5000);  // oldest first
  absl::StatusOr<LeasedCounts> counts = store_->CountLeasedCommands(job->job.id, now_ms_);
  ASSERT_TRUE(counts.ok()) << counts.status();
  EXPECT_EQ(counts->total, 3);
  EXPECT_EQ(counts->by_level, (std::map<int, int>{{0, 2}, {1, 1}}));
}

TEST_F(SqliteStoreTest, AcceptTraceCanLeaseTheNextCommandInTheSameWrite) {
  CreatedJob job = Job(3);
  CommandRecord command = Lease(job.job.id, "rig-a");
  AcceptTraceRequest request = MakeTestAccept(command, 20);
  request.lease_next = LeaseRequest{job.job.id, "rig-a", now_ms_, 30'000};
  absl::StatusOr<AcceptTraceResult> result = store_->AcceptTrace(request);
  ASSERT_TRUE(result.ok()) << result.status();
  ASSERT_TRUE(result->next_command.has_value());
  EXPECT_NE(result->next_command->id, command.id);
  EXPECT_EQ(result->next_command->state, CommandState::kLeased);
  EXPECT_EQ(result->next_command->lease_owner, "rig-a");
  EXPECT_EQ(result->next_command->lease_deadline_unix_ms, kStartMs + 30'000);
  EXPECT_EQ(store_->CountLeasedCommands(job.job.id, now_ms_)->total, 1);

  // A write that fails leases nothing: the next command stays pending.
  AcceptTraceRequest broken = MakeTestAccept(*result->next_command, 20);
  broken.events.push_back(NewEvent{"note", "{broken"});
  broken.lease_next = LeaseRequest{job.job.id, "rig-a", now_ms_, 30'000};
  auto before = TableCounts();
  EXPECT_FALSE(store_->AcceptTrace(broken).ok());
  EXPECT_EQ(TableCounts(), before);

  // An invalid lease request is rejected before anything is written.
  AcceptTraceRequest bad_lease = MakeTestAccept(*result->next_command, 20);
  bad_lease.lease_next = LeaseRequest{job.job.id, "", now_ms_, 30'000};
  EXPECT_EQ(store_->AcceptTrace(bad_lease).status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(TableCounts(), before);
}

TEST_F(SqliteStoreTest, AnIdenticalRetryFromTheSameRigIsAlreadyAccepted) {
  CreatedJob job = Job(2);
  CommandRecord command = Lease(job.job.id, "rig-a");
  AcceptTraceRequest request = MakeTestAccept(command, 50);
  request.new_commands = {MakeTestCommand(1, 3)};
  absl::StatusOr<AcceptTraceResult> first = store_->AcceptTrace(request);
  ASSERT_TRUE(first.ok()) << first.status();
  auto after_first = TableCounts();

  // The rig retries with the same samples (its reply was lost).
  now_ms_ += 5'000;
  absl::StatusOr<AcceptTraceResult> retry = store_->AcceptTrace(request);
  ASSERT_TRUE(retry.ok()) << retry.status();
  EXPECT_TRUE(retry->already_accepted);
  EXPECT_EQ(retry->trace_id, first->trace_id);
  EXPECT_EQ(retry->fit_id, first->fit_id);
  ASSERT_TRUE(retry->fit.has_value()) << "a retry answers with the stored fit";
  EXPECT_EQ(retry->fit->id, first->fit->id);
  EXPECT_EQ(retry->fit->mu, first->fit->mu);
  EXPECT_EQ(retry->accepted_unix_ms, first->accepted_unix_ms) << "the first acceptance's time, not now";
  EXPECT_EQ(retry->plan_revision, first->plan_revision);
  EXPECT_EQ(TableCounts(), after_first);

  // Same command under the wrong job is an error, not a silent success.
  AcceptTraceRequest wrong_job = request;
  wrong_job.job_id = job.job.id + 1;
  EXPECT_EQ(store_->AcceptTrace(wrong_job).status().code(), absl::StatusCode::kInvalidArgument);

  // Still a retry after the job was cancelled: the trace is stored, so saying
  // "not accepted" would be false.
  ASSERT_TRUE(store_->UpdateJobState(JobStateChange{job.job.id, JobState::kCancelled, {}}).ok());
  retry = store_->AcceptTrace(request);
  ASSERT_TRUE(retry.ok()) << retry.status();
  EXPECT_TRUE(retry->already_accepted);
}

TEST_F(SqliteStoreTest, ARepeatedSubmissionWithOtherSamplesIsRefusedAndChangesNothing) {
  CreatedJob job = Job(2);
  CommandRecord command = Lease(job.job.id, "rig-a");
  AcceptTraceRequest request = MakeTestAccept(command, 50);
  ASSERT_TRUE(store_->AcceptTrace(request).ok());
  auto after_first = TableCounts();
  request.samples = MakeTestSamples(50, 99);  // same length, other values
  absl::StatusOr<AcceptTraceResult> other = store_->AcceptTrace(request);
  EXPECT_EQ(other.status().code(), absl::StatusCode::kAlreadyExists) << other.status();
  EXPECT_NE(other.status().message().find("differ"), std::string::npos) << other.status();
  EXPECT_NE(other.status().message().find("rig-a"), std::string::npos) << other.status();
  request.samples = MakeTestSamples(10, 1);  // other length
  EXPECT_EQ(store_->AcceptTrace(request).status().code(), absl::StatusCode::kAlreadyExists);
  EXPECT_EQ(TableCounts(), after_first);
}

TEST_F(SqliteStoreTest, ALateTraceFromAnExpiredLesseeIsRefusedNamingTheRigThatMeasured) {
  CreatedJob job = Job(1);
  CommandRecord first_lease = Lease(job.job.id, "rig-a", kStartMs, 1'000);
  // rig-a's lease expires; rig-b leases the command again.
  CommandRecord second_lease = Lease(job.job.id, "rig-b", kStartMs + 2'000);
  ASSERT_EQ(second_lease.id, first_lease.id);
  AcceptTraceRequest from_a = MakeTestAccept(first_lease, 50);
  from_a.lease_owner = "rig-a";
  // Before rig-b answers: rig-a no longer holds the lease.
  absl::StatusOr<AcceptTraceResult> early = store_->AcceptTrace(from_a);
  EXPECT_EQ(early.status().code(), absl::StatusCode::kFailedPrecondition) << early.status();
  EXPECT_NE(early.status().message().find("expired"), std::string::npos) << early.status();
  // rig-b answers; then rig-a's late trace must not be acknowledged.
  AcceptTraceRequest from_b = MakeTestAccept(second_lease, 60);
  from_b.lease_owner = "rig-b";
  absl::StatusOr<AcceptTraceResult> accepted = store_->AcceptTrace(from_b);
  ASSERT_TRUE(accepted.ok()) << accepted.status();
  auto after_b = TableCounts();
  absl::StatusOr<AcceptTraceResult> late = store_->AcceptTrace(from_a);
  EXPECT_EQ(late.status().code(), absl::StatusCode::kAlreadyExists) << late.status();
  EXPECT_NE(late.status().message().find("rig-b"), std::string::npos) << late.status();
  EXPECT_EQ(TableCounts(), after_b);
  // rig-b's own retry is still recognised.
  absl::StatusOr<AcceptTraceResult> retry = store_->AcceptTrace(from_b);
  ASSERT_TRUE(retry.ok()) << retry.status();
  EXPECT_TRUE(retry->already_accepted);
}

TEST_F(SqliteStoreTest, ARetryWithLeaseNextGetsBackTheCommandTheFirstWriteLeased) {
  CreatedJob job = Job(3);
  CommandRecord command = Lease(job.job.id, "rig-a");
  AcceptTraceRequest request = MakeTestAccept(command, 50);
  request.lease_next = LeaseRequest{job.job.id, "rig-a", kStartMs, 30'000};
  absl::StatusOr<AcceptTraceResult> first = store_->AcceptTrace(request);
  ASSERT_TRUE(first.ok()) << first.status();
  ASSERT_TRUE(first->next_command.has_value());
  auto after_first = TableCounts();
  absl::StatusOr<AcceptTraceResult> retry = store_->AcceptTrace(request);
  ASSERT_TRUE(retry.ok()) << retry.status();
  ASSERT_TRUE(retry->next_command.has_value());
  EXPECT_EQ(retry->next_command->id, first->next_command->id) << "a second command would be orphaned";
  EXPECT_EQ(TableCounts(), after_first);
  EXPECT_EQ(store_->CountLeasedCommands(job.job.id, kStartMs)->total, 1);
}

TEST_F(SqliteStoreTest, SamplesAreReadWithTheirCommandAndFitInOneSnapshot) {
  CreatedJob job = Job(3);
  std::vector<int64_t> traces;
  for (int i = 0; i < 2; ++i) {
    CommandRecord command = Lease(job.job.id, absl::StrCat("rig-", i));
    absl::StatusOr<AcceptTraceResult> r = store_->AcceptTrace(MakeTestAccept(command, 20 + i));
    ASSERT_TRUE(r.ok()) << r.status();
    traces.push_back(r->trace_id);
  }
  absl::StatusOr<std::vector<SampleRecord>> samples = store_->ReadJobSamples(job.job.id, 0);
  ASSERT_TRUE(samples.ok()) << samples.status();
  ASSERT_EQ(samples->size(), 2u);
  for (size_t i = 0; i < 2; ++i) {
    const SampleRecord& s = (*samples)[i];
    EXPECT_EQ(s.trace.id, traces[i]);
    EXPECT_EQ(s.command.id, s.trace.command_id);
    EXPECT_EQ(s.command.lease_owner, absl::StrCat("rig-", i)) << "the rig that measured it";
    EXPECT_EQ(s.fit.trace_id, s.trace.id);
    EXPECT_EQ(s.fit.version, 1);
    EXPECT_TRUE(s.trace.samples.empty());
  }
  ASSERT_TRUE(store_->AddFits({TraceRefit{traces[0], MakeTestFit(0.7)}}).ok());
  samples = store_->ReadJobSamples(job.job.id, 0);
  ASSERT_TRUE(samples.ok());
  EXPECT_EQ((*samples)[0].fit.version, 2) << "latest fit per trace";
  EXPECT_EQ((*samples)[1].fit.version, 1);
  samples = store_->ReadJobSamples(job.job.id, 2);
  ASSERT_TRUE(samples.ok());
  EXPECT_EQ(samples->size(), 1u) << "only traces with a fit of version 2";

  absl::StatusOr<SampleRecord> one = store_->ReadSample(traces[1], 0, /*include_samples=*/true);
  ASSERT_TRUE(one.ok()) << one.status();
  EXPECT_EQ(one->trace.samples.size(), 21u);
  EXPECT_EQ(one->fit.version, 1);
  EXPECT_EQ(store_->ReadSample(traces[1], 5, false).status().code(), absl::StatusCode::kNotFound);
  EXPECT_EQ(store_->ReadSample(999, 0, false).status().code(), absl::StatusCode::kNotFound);
  EXPECT_EQ(store_->ReadJobSamples(999, 0).status().code(), absl::StatusCode::kNotFound);
}

TEST_F(SqliteStoreTest, TracesPageInIdOrder) {
  CreatedJob job = Job(5);
  for (int i = 0; i < 5; ++i) {
    CommandRecord command = Lease(job.job.id, "rig");
    ASSERT_TRUE(store_->AcceptTrace(MakeTestAccept(command, 10 + i)).ok());
  }
  std::vector<int64_t> seen;
  int64_t after = 0;
  for (;;) {
    absl::StatusOr<std::vector<TraceRecord>> page = store_->ListTracesPage(job.job.id, after, 2, true);
    ASSERT_TRUE(page.ok()) << page.status();
    if (page->empty()) break;
    EXPECT_LE(page->size(), 2u);
    for (const TraceRecord& t : *page) {
      EXPECT_EQ(static_cast<int64_t>(t.samples.size()), t.n_samples);
      seen.push_back(t.id);
      after = t.id;
    }
  }
  EXPECT_EQ(seen.size(), 5u);
  EXPECT_TRUE(std::is_sorted(seen.begin(), seen.end()));
  EXPECT_EQ(store_->ListTracesPage(job.job.id, 0, 0, false).status().code(), absl::StatusCode::kInvalidArgument);
}

TEST_F(SqliteStoreTest, ActiveJobsAreTheRunningAndPausedOnes) {
  CreatedJob running = Job(1), paused = Job(1), cancelled = Job(1);
  ASSERT_TRUE(store_->UpdateJobState(JobStateChange{paused.job.id, JobState::kPaused, {}}).ok());
  ASSERT_TRUE(store_->UpdateJobState(JobStateChange{cancelled.job.id, JobState::kCancelled, {}}).ok());
  absl::StatusOr<std::vector<JobRecord>> active = store_->ListActiveJobs();
  ASSERT_TRUE(active.ok()) << active.status();
  ASSERT_EQ(active->size(), 2u);
  EXPECT_EQ((*active)[0].id, running.job.id);
  EXPECT_EQ((*active)[1].id, paused.job.id);
}

TEST_F(SqliteStoreTest, SyncRunsAfterEveryEarlierWrite) {
  CreatedJob job = Job(20);
  std::vector<std::future<void>> done;
  std::atomic<int> completed{0};
  for (int i = 0; i < 20; ++i) {
    store_->LeaseNextCommandAsync(LeaseRequest{job.job.id, "rig", kStartMs, 60'000},
                                  [&](absl::StatusOr<std::optional<CommandRecord>>) { completed.fetch_add(1); });
  }
  std::promise<int> at_sync;
  store_->SyncAsync([&](absl::Status s) { at_sync.set_value(s.ok() ? completed.load() : -1); });
  EXPECT_EQ(at_sync.get_future().get(), 20);
}

TEST_F(SqliteStoreTest, AcceptTraceThatFailsHalfWayLeavesDatabaseUnchanged) {
  CreatedJob job = Job(2);
  CommandRecord command = Lease(job.job.id, "rig-a");
  auto before = TableCounts();
  // Everything valid up to the last write: the event's detail is not JSON.
  AcceptTraceRequest request = MakeTestAccept(command, 200);
  request.new_commands = {MakeTestCommand(1, 1), MakeTestCommand(1, 2)};
  request.new_job_state = JobState::kPaused;
  request.events.push_back(NewEvent{"note", "{broken"});
  absl::StatusOr<AcceptTraceResult> result = store_->AcceptTrace(request);
  ASSERT_FALSE(result.ok());
  EXPECT_EQ(result.status().code(), absl::StatusCode::kInvalidArgument) << result.status();
  EXPECT_NE(result.status().message().find("events[1]"), std::string::npos) << result.status();
  EXPECT_NE(result.status().message().find("command " + std::to_string(command.id)),
            std::string::npos);
  EXPECT_EQ(TableCounts(), before);
  EXPECT_EQ(store_->GetCommand(command.id)->state, CommandState::kLeased);

  // Same with a bad new command in the middle.
  request.events.pop_back();
  request.new_commands[1].command_json = "[";
  ASSERT_FALSE(store_->AcceptTrace(request).ok());
  EXPECT_EQ(TableCounts(), before);

  // Fixed, it goes through.
  request.new_commands[1] = MakeTestCommand(1, 2);
  EXPECT_TRUE(store_->AcceptTrace(request).ok());
  EXPECT_EQ(store_->GetJob(job.job.id)->state, JobState::kPaused);
}

TEST_F(SqliteStoreTest, AcceptTraceRefusesCommandsInTheWrongState) {
  CreatedJob job = Job(3);
  // Never leased.
  CommandRecord pending = *store_->GetCommand(job.command_ids[2]);
  absl::StatusOr<AcceptTraceResult> r = store_->AcceptTrace(MakeTestAccept(pending, 10));
  EXPECT_EQ(r.status().code(), absl::StatusCode::kFailedPrecondition) << r.status();
  EXPECT_NE(r.status().message().find("pending, not leased"), std::string::npos) << r.status();

  // Leased to someone else.
  CommandRecord command = Lease(job.job.id, "rig-a");
  AcceptTraceRequest request = MakeTestAccept(command, 10);
  request.lease_owner = "rig-b";
  r = store_->AcceptTrace(request);
  EXPECT_EQ(r.status().code(), absl::StatusCode::kFailedPrecondition);
  EXPECT_NE(r.status().message().find("leased to 'rig-a'"), std::string::npos) << r.status();

  // Unknown command.
  request.command_id = 12345;
  EXPECT_EQ(store_->AcceptTrace(request).status().code(), absl::StatusCode::kNotFound);

  // Cancelled job: refused, nothing written.
  ASSERT_TRUE(store_->UpdateJobState(JobStateChange{job.job.id, JobState::kCancelled,
                                                    {NewEvent{"job_cancelled", "{}"}}})
                  .ok());
  auto before = TableCounts();
  r = store_->AcceptTrace(MakeTestAccept(command, 10));
  EXPECT_EQ(r.status().code(), absl::StatusCode::kFailedPrecondition);
  EXPECT_NE(r.status().message().find("cancelled"), std::string::npos) << r.status();
  EXPECT_EQ(TableCounts(), before);

  // No samples: rejected before queuing.
  AcceptTraceRequest empty = MakeTestAccept(command, 10);
  empty.samples.clear();
  EXPECT_EQ(store_->AcceptTrace(empty).status().code(), absl::StatusCode::kInvalidArgument);
}

TEST_F(SqliteStoreTest, FailCommandMarksItFailedWithThePlanChangeOrWritesNothing) {
  CreatedJob job = Job(2);
  CommandRecord command = Lease(job.job.id, "rig-a");
  auto fail_command = [&](FailCommandRequest request) {
    std::promise<absl::StatusOr<FailCommandResult>> promise;
    store_->FailCommandAsync(std::move(request),
                             [&promise](absl::StatusOr<FailCommandResult> r) { promise.set_value(std::move(r)); });
    return promise.get_future().get();
  };
  FailCommandRequest request;
  request.command_id = command.id;
  request.job_id = job.job.id;
  request.lease_owner = "rig-b";  // not the holder: refused, nothing written
  request.reason = "probe slipped";
  request.new_plan_json = R"({"retry": true})";
  request.expected_plan_revision = 1;
  request.new_commands = {MakeTestCommand(0, 7)};
  request.events = {NewEvent{"probe_failed", "{}"}};
  auto before = TableCounts();
  absl::StatusOr<FailCommandResult> r = fail_command(request);
  EXPECT_EQ(r.status().code(), absl::StatusCode::kFailedPrecondition) << r.status();
  EXPECT_NE(r.status().message().find("leased to 'rig-a'"), std::string::npos) << r.status();
  EXPECT_EQ(TableCounts(), before);

  request.lease_owner = "rig-a";
  r = fail_command(request);
  ASSERT_TRUE(r.ok()) << r.status();
  EXPECT_EQ(r->plan_revision, 2);
  ASSERT_EQ(r->new_command_ids.size(), 1u);
  EXPECT_EQ(store_->GetCommand(command.id)->state, CommandState::kFailed);
  EXPECT_EQ(store_->GetPlan(job.job.id)->plan_json, R"({"retry": true})");
  EXPECT_EQ(store_->GetCommand(r->new_command_ids[0])->state, CommandState::kPending);

  // A failed command cannot fail again.
  r = fail_command(request);
  EXPECT_EQ(r.status().code(), absl::StatusCode::kFailedPrecondition) << r.status();
  EXPECT_NE(r.status().message().find("failed, not leased"), std::string::npos) << r.status();
}

TEST_F(SqliteStoreTest, StalePlanRevisionIsAborted) {
  CreatedJob job = Job(2);
  CommandRecord a = Lease(job.job.id, "rig-a");
  CommandRecord b = Lease(job.job.id, "rig-b");
  AcceptTraceRequest ra = MakeTestAccept(a, 10);
  AcceptTraceRequest rb = MakeTestAccept(b, 10);
  ra.expected_plan_revision = 1;
  rb.expected_plan_revision = 1;  // computed from the same plan
  ASSERT_TRUE(store_->AcceptTrace(ra).ok());
  absl::StatusOr<AcceptTraceResult> r = store_->AcceptTrace(rb);
  EXPECT_EQ(r.status().code(), absl::StatusCode::kAborted) << r.status();
  rb.expected_plan_revision = 2;
  r = store_->AcceptTrace(rb);
  ASSERT_TRUE(r.ok()) << r.status();
  EXPECT_EQ(r->plan_revision, 3);
}

TEST_F(SqliteStoreTest, ExpiredLeaseIsReissuedAndLiveLeaseIsNot) {
  CreatedJob job = Job(1);
  CommandRecord first = Lease(job.job.id, "rig-a", kStartMs, 1000);
  EXPECT_EQ(first.lease_deadline_unix_ms, kStartMs + 1000);
  // Still leased: nothing to hand out.
  absl::StatusOr<std::optional<CommandRecord>> none =
      store_->LeaseNextCommand(LeaseRequest{job.job.id, "rig-b", kStartMs + 999, 1000});
  ASSERT_TRUE(none.ok());
  EXPECT_FALSE(none->has_value());
  // At the deadline the lease has expired.
  CommandRecord again = Lease(job.job.id, "rig-b", kStartMs + 1000, 1000);
  EXPECT_EQ(again.id, first.id);
  EXPECT_EQ(again.lease_owner, "rig-b");
  EXPECT_EQ(again.attempt, 2);
  // The first rig's late trace is refused (the lease moved); rig-b's is accepted.
  AcceptTraceRequest late = MakeTestAccept(first, 10);
  EXPECT_EQ(store_->AcceptTrace(late).status().code(), absl::StatusCode::kFailedPrecondition);
  EXPECT_TRUE(store_->AcceptTrace(MakeTestAccept(again, 10)).ok());
}

TEST_F(SqliteStoreTest, LeasingSkipsPausedJobsAndHonoursJobFilter) {
  CreatedJob j1 = Job(1);
  CreatedJob j2 = Job(1);
  ASSERT_TRUE(store_->UpdateJobState(JobStateChange{j1.job.id, JobState::kPaused, {}}).ok());
  CommandRecord any = Lease(0, "rig-a");
  EXPECT_EQ(any.job_id, j2.job.id);
  absl::StatusOr<std::optional<CommandRecord>> none =
      store_->LeaseNextCommand(LeaseRequest{j1.job.id, "rig-a", kStartMs, 1000});
  ASSERT_TRUE(none.ok());
  EXPECT_FALSE(none->has_value());
  EXPECT_EQ(store_->LeaseNextCommand(LeaseRequest{999, "rig-a", kStartMs, 1000}).status().code(),
            absl::StatusCode::kNotFound);
  EXPECT_EQ(store_->LeaseNextCommand(LeaseRequest{0, "", kStartMs, 1000}).status().code(),
            absl::StatusCode::kInvalidArgument);
}

TEST_F(SqliteStoreTest, ConcurrentLeasingNeverHandsACommandOutTwice) {
  constexpr int kCommands = 300;
  constexpr int kThreads = 12;
  CreatedJob job = Job(kCommands);
  std::vector<std::vector<int64_t>> got(kThreads);
  std::vector<std::thread> threads;
  for (int t = 0; t < kThreads; ++t) {
    threads.emplace_back([this, t, &got] {
      const std::string owner = "rig-" + std::to_string(t);
      while (true) {
        absl::StatusOr<std::optional<CommandRecord>> c =
            store_->LeaseNextCommand(LeaseRequest{0, owner, kStartMs, 60'000});
        if (!c.ok() || !c->has_value()) return;
        EXPECT_EQ((*c)->lease_owner, owner);
        got[t].push_back((*c)->id);
      }
    });
  }
  for (std::thread& th : threads) th.join();
  std::set<int64_t> distinct;
  size_t total = 0;
  for (const auto& ids : got) {
    total += ids.size();
    distinct.insert(ids.begin(), ids.end());
  }
  EXPECT_EQ(total, static_cast<size_t>(kCommands));
  EXPECT_EQ(distinct.size(), static_cast<size_t>(kCommands));
  // Held in a variable: `*store_->ListCommands(...)` in a range-for would
  // iterate a temporary that is already destroyed (ThreadSanitizer found it).
  absl::StatusOr<std::vector<CommandRecord>> commands = store_->ListCommands(job.job.id);
  ASSERT_TRUE(commands.ok()) << commands.status();
  for (const CommandRecord& c : *commands) {
    EXPECT_EQ(c.state, CommandState::kLeased);
    EXPECT_EQ(c.attempt, 1);
  }
  // Group commit did batch the concurrent leases.
  EXPECT_GT(store_->writer_stats().writes, store_->writer_stats().transactions);
}

TEST_F(SqliteStoreTest, ConcurrentAcceptsFromManyRigsAllLand) {
  constexpr int kCommands = 64;
  constexpr int kThreads = 8;
  CreatedJob job = Job(kCommands);
  std::atomic<int> accepted{0};
  std::vector<std::thread> threads;
  for (int t = 0; t < kThreads; ++t) {
    threads.emplace_back([this, t, &accepted] {
      const std::string owner = "rig-" + std::to_string(t);
      while (true) {
        absl::StatusOr<std::optional<CommandRecord>> c =
            store_->LeaseNextCommand(LeaseRequest{0, owner, kStartMs, 60'000});
        if (!c.ok() || !c->has_value()) return;
        AcceptTraceRequest r = MakeTestAccept(**c, 300);
        r.new_plan_json.clear();  // plan updates from concurrent rigs would conflict
        absl::StatusOr<AcceptTraceResult> result = store_->AcceptTrace(r);
        EXPECT_TRUE(result.ok()) << result.status();
        if (result.ok()) ++accepted;
      }
    });
  }
  for (std::thread& th : threads) th.join();
  EXPECT_EQ(accepted.load(), kCommands);
  absl::StatusOr<std::vector<TraceRecord>> traces = store_->ListTraces(job.job.id, true);
  ASSERT_TRUE(traces.ok());
  ASSERT_EQ(traces->size(), static_cast<size_t>(kCommands));
  for (const TraceRecord& t : *traces) {
    std::vector<StoredSample> expected = MakeTestSamples(300, static_cast<uint64_t>(t.command_id));
    ASSERT_EQ(t.samples.size(), expected.size());
    for (size_t i = 0; i < expected.size(); ++i) ASSERT_TRUE(BitwiseEqual(t.samples[i], expected[i]));
  }
}

TEST_F(SqliteStoreTest, JobStateTransitions) {
  CreatedJob job = Job(1);
  absl::StatusOr<JobRecord> paused =
      store_->UpdateJobState(JobStateChange{job.job.id, JobState::kPaused, {NewEvent{"paused"}}});
  ASSERT_TRUE(paused.ok());
  EXPECT_EQ(paused->state, JobState::kPaused);
  ASSERT_TRUE(store_->UpdateJobState(JobStateChange{job.job.id, JobState::kRunning, {}}).ok());
  ASSERT_TRUE(store_->UpdateJobState(JobStateChange{job.job.id, JobState::kCompleted, {}}).ok());
  absl::StatusOr<JobRecord> again =
      store_->UpdateJobState(JobStateChange{job.job.id, JobState::kRunning, {NewEvent{"x"}}});
  EXPECT_EQ(again.status().code(), absl::StatusCode::kFailedPrecondition);
  EXPECT_NE(again.status().message().find("from completed to running"), std::string::npos)
      << again.status();
  EXPECT_EQ(store_->ListEvents(job.job.id, 0, 100)->size(), 2u);  // created, paused
  absl::StatusOr<std::vector<JobRecord>> jobs = store_->ListJobs(job.job.object_id);
  ASSERT_EQ(jobs->size(), 1u);
  EXPECT_EQ((*jobs)[0].state, JobState::kCompleted);
}

TEST_F(SqliteStoreTest, RefitsGetOneVersionPerBatchAndListFitsSelectsVersions) {
  CreatedJob job = Job(3);
  std::vector<int64_t> trace_ids;
  for (int i = 0; i < 3; ++i) {
    CommandRecord c = Lease(job.job.id, "rig");
    AcceptTraceRequest r = MakeTestAccept(c, 20);
    if (i == 2) r.fit.reset();  // a trace stored without a fit
    trace_ids.push_back(store_->AcceptTrace(r)->trace_id);
  }
  EXPECT_EQ(store_->ListFits(job.job.id, 1)->size(), 2u);

  // Refit traces 0 and 2: one version for the batch (2), though trace 2 had none.
  NewFit refit = MakeTestFit(0.2);
  refit.estimator_version = "2.0.0";
  refit.a1.reset();
  absl::StatusOr<std::vector<FitRecord>> added =
      store_->AddFits({TraceRefit{trace_ids[0], refit}, TraceRefit{trace_ids[2], refit}});
  ASSERT_TRUE(added.ok()) << added.status();
  ASSERT_EQ(added->size(), 2u);
  EXPECT_EQ((*added)[0].version, 2);
  EXPECT_EQ((*added)[1].version, 2);

  absl::StatusOr<FitRecord> latest = store_->GetFit(trace_ids[0], 0);
  EXPECT_EQ(latest->version, 2);
  EXPECT_EQ(latest->estimator_version, "2.0.0");
  EXPECT_FALSE(latest->a1.has_value());
  EXPECT_EQ(store_->GetFit(trace_ids[0], 1)->estimator_version, "1.0.0");
  EXPECT_EQ(store_->GetFit(trace_ids[1], 2).status().code(), absl::StatusCode::kNotFound);

  absl::StatusOr<std::vector<FitRecord>> v2 = store_->ListFits(job.job.id, 2);
  ASSERT_EQ(v2->size(), 2u);
  absl::StatusOr<std::vector<FitRecord>> newest = store_->ListFits(job.job.id, 0);
  ASSERT_EQ(newest->size(), 3u);
  EXPECT_EQ((*newest)[0].version, 2);
  EXPECT_EQ((*newest)[1].version, 1);
  EXPECT_EQ((*newest)[2].version, 2);

  // A batch naming an unknown trace writes nothing.
  auto before = TableCounts();
  absl::StatusOr<std::vector<FitRecord>> bad =
      store_->AddFits({TraceRefit{trace_ids[1], refit}, TraceRefit{424242, refit}});
  EXPECT_EQ(bad.status().code(), absl::StatusCode::kNotFound);
  EXPECT_NE(bad.status().message().find("fits[1]: trace 424242"), std::string::npos)
      << bad.status();
  EXPECT_EQ(TableCounts(), before);
  EXPECT_EQ(store_->AddFits({TraceRefit{trace_ids[1], refit}, TraceRefit{trace_ids[1], refit}})
                .status()
                .code(),
            absl::StatusCode::kInvalidArgument);
}

TEST_F(SqliteStoreTest, EventsPageByIdAcrossJobs) {
  CreatedJob j1 = Job(1);
  CreatedJob j2 = Job(1);
  for (int i = 0; i < 5; ++i) {
    ASSERT_TRUE(store_->UpdateJobState(JobStateChange{
        j1.job.id, i % 2 == 0 ? JobState::kPaused : JobState::kRunning, {NewEvent{"toggle"}}}).ok());
  }
  absl::StatusOr<std::vector<EventRecord>> all = store_->ListEvents(0, 0, 100);
  ASSERT_EQ(all->size(), 7u);
  for (size_t i = 1; i < all->size(); ++i) EXPECT_GT((*all)[i].id, (*all)[i - 1].id);
  absl::StatusOr<std::vector<EventRecord>> page = store_->ListEvents(j1.job.id, (*all)[2].id, 2);
  ASSERT_EQ(page->size(), 2u);
  EXPECT_EQ((*page)[0].kind, "toggle");
  EXPECT_GT((*page)[0].id, (*all)[2].id);
  EXPECT_EQ(store_->ListEvents(j2.job.id, 0, 100)->size(), 1u);
  EXPECT_EQ(store_->ListEvents(0, 0, 0).status().code(), absl::StatusCode::kInvalidArgument);
}

TEST_F(SqliteStoreTest, EventsPageBackFromTheNewest) {
  CreatedJob j1 = Job(1);
  CreatedJob j2 = Job(1);
  for (int i = 0; i < 5; ++i) {
    ASSERT_TRUE(store_->UpdateJobState(JobStateChange{
        j1.job.id, i % 2 == 0 ? JobState::kPaused : JobState::kRunning, {NewEvent{"toggle"}}}).ok());
  }
  absl::StatusOr<std::vector<EventRecord>> all = store_->ListEvents(j1.job.id, 0, 100);
  ASSERT_TRUE(all.ok()) << all.status();
  ASSERT_EQ(all->size(), 6u);  // created + 5 toggles
  absl::StatusOr<std::vector<EventRecord>> newest = store_->ListEventsNewestFirst(j1.job.id, 0, 4);
  ASSERT_TRUE(newest.ok()) << newest.status();
  ASSERT_EQ(newest->size(), 4u);
  for (size_t i = 0; i < 4; ++i) EXPECT_EQ((*newest)[i].id, (*all)[5 - i].id);
  absl::StatusOr<std::vector<EventRecord>> older = store_->ListEventsNewestFirst(j1.job.id, newest->back().id, 4);
  ASSERT_TRUE(older.ok()) << older.status();
  ASSERT_EQ(older->size(), 2u);  // the rest, and nothing of the other job
  EXPECT_EQ((*older)[0].id, (*all)[1].id);
  EXPECT_EQ((*older)[1].id, (*all)[0].id);
  EXPECT_EQ(store_->ListEventsNewestFirst(j2.job.id, 0, 100)->size(), 1u);
  EXPECT_EQ(store_->ListEventsNewestFirst(0, 0, 0).status().code(), absl::StatusCode::kInvalidArgument);
}

TEST_F(SqliteStoreTest, ReopenKeepsEverything) {
  CreatedJob job = Job(2);
  CommandRecord c = Lease(job.job.id, "rig-a");
  AcceptTraceRequest r = MakeTestAccept(c, 123);
  absl::StatusOr<AcceptTraceResult> result = store_->AcceptTrace(r);
  ASSERT_TRUE(result.ok());
  auto before = TableCounts();
  Reopen();
  EXPECT_EQ(TableCounts(), before);
  absl::StatusOr<TraceRecord> trace = store_->GetTrace(result->trace_id, true);
  ASSERT_TRUE(trace.ok());
  ASSERT_EQ(trace->samples.size(), 123u);
  for (size_t i = 0; i < r.samples.size(); ++i) EXPECT_TRUE(BitwiseEqual(trace->samples[i], r.samples[i]));
  // Leasing continues where it stopped.
  EXPECT_EQ(Lease(job.job.id, "rig-a").id, job.command_ids[1]);
}

TEST_F(SqliteStoreTest, AsyncCallbacksRunAfterCommit) {
  CreatedJob job = Job(4);
  std::vector<CommandRecord> leased;
  for (int i = 0; i < 4; ++i) leased.push_back(Lease(job.job.id, "rig"));
  std::mutex mu;
  std::condition_variable cv;
  int done = 0;
  std::vector<int64_t> trace_ids;
  for (const CommandRecord& c : leased) {
    AcceptTraceRequest r = MakeTestAccept(c, 30);
    r.new_plan_json.clear();
    store_->AcceptTraceAsync(std::move(r), [&, path = path_](absl::StatusOr<AcceptTraceResult> res) {
      ASSERT_TRUE(res.ok()) << res.status();
      // Visible to a brand-new connection: committed before the callback.
      auto db = SqliteConnection::Open(path, {});
      absl::StatusOr<SqliteStatement> q = (*db)->Prepare("SELECT COUNT(*) FROM traces WHERE id = ?1");
      q->BindInt(1, res->trace_id);
      EXPECT_TRUE(*q->Step());
      EXPECT_EQ(q->ColumnInt(0), 1);
      std::lock_guard<std::mutex> lock(mu);
      trace_ids.push_back(res->trace_id);
      ++done;
      cv.notify_all();
    });
  }
  std::unique_lock<std::mutex> lock(mu);
  cv.wait(lock, [&] { return done == 4; });
  EXPECT_EQ(std::set<int64_t>(trace_ids.begin(), trace_ids.end()).size(), 4u);
}

TEST_F(SqliteStoreTest, BackgroundCheckpointKeepsWalBounded) {
  // Small thresholds: wake at 400 KB, catch up inline at 1.6 MB. 150 traces
  // of 1,000 samples put ~8.6 MB through the WAL.
  SqliteStoreOptions options;
  options.checkpoint.wake_bytes = 400 << 10;
  options.checkpoint.inline_bytes = 1600 << 10;
  Reopen(options);
  CreatedJob job = Job(150);
  for (int i = 0; i < 150; ++i) {
    CommandRecord c = Lease(job.job.id, "rig");
    AcceptTraceRequest r = MakeTestAccept(c, 1000);
    r.new_plan_json.clear();
    ASSERT_TRUE(store_->AcceptTrace(r).ok());
  }
  // The checkpointer runs asynchronously; it was woken several times.
  for (int wait = 0; wait < 200 && store_->background_checkpoints() < 2; ++wait) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  EXPECT_GE(store_->background_checkpoints(), 2);
  // The WAL file keeps its high-water size; without restarts it would hold
  // all 8.6 MB. The bound is the inline threshold plus one batch (here one
  // ~70 KB trace) and some pages of slack; before the writer took its turn
  // from a running background pass, a loaded machine went past 4 MB.
  const auto wal_bytes = std::filesystem::file_size(path_ + "-wal");
  EXPECT_LT(wal_bytes, (1600u << 10) + (512u << 10)) << "WAL grew past inline_bytes + one batch";
  std::cerr << "[ info ] WAL " << wal_bytes << " bytes, DB "
            << std::filesystem::file_size(path_) << " bytes, "
            << store_->background_checkpoints() << " background checkpoints\n";
  absl::StatusOr<std::vector<TraceRecord>> traces = store_->ListTraces(job.job.id, true);
  ASSERT_TRUE(traces.ok());
  EXPECT_EQ(traces->size(), 150u);
}

}  // namespace
}  // namespace surfmap

namespace surfmap {
namespace {

// Frames and calibration (schema version 5).
TEST_F(SqliteStoreTest, RigRegistrationsAreVersionedPerObjectAndRigAndNeverChanged) {
  CreatedJob job = Job(2);
  const int64_t object = job.job.object_id;
  const std::string json_a = R"({"tip_radius_mm": 1})", json_b = R"({"tip_radius_mm": 2})";
  absl::StatusOr<RigRegistrationRecord> a1 = store_->AddRigRegistration({object, "arm", json_a});
  absl::StatusOr<RigRegistrationRecord> b1 = store_->AddRigRegistration({object, "other", json_a});
  absl::StatusOr<RigRegistrationRecord> a2 = store_->AddRigRegistration({object, "arm", json_b});
  ASSERT_TRUE(a1.ok() && b1.ok() && a2.ok()) << a1.status() << b1.status() << a2.status();
  EXPECT_EQ(a1->version, 1);
  EXPECT_EQ(b1->version, 1);
  EXPECT_EQ(a2->version, 2);
  EXPECT_EQ(a2->registration_json, json_b);
  absl::StatusOr<RigRegistrationRecord> old = store_->GetRigRegistration(a1->id);
  ASSERT_TRUE(old.ok());
  EXPECT_EQ(old->registration_json, json_a);  // the older version stays as it was
  absl::StatusOr<std::vector<RigRegistrationRecord>> all = store_->ListRigRegistrations(object);
  ASSERT_TRUE(all.ok());
  ASSERT_EQ(all->size(), 3u);
  EXPECT_EQ((*all)[2].id, a2->id);

  EXPECT_EQ(store_->AddRigRegistration({999, "arm", json_a}).status().code(), absl::StatusCode::kNotFound);
  EXPECT_EQ(store_->AddRigRegistration({object, "", json_a}).status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_FALSE(store_->AddRigRegistration({object, "arm", "{not json"}).ok());
  EXPECT_EQ(store_->GetRigRegistration(12345).status().code(), absl::StatusCode::kNotFound);

  // A trace records the frame it was sent in; object-frame traces have none.
  CommandRecord command = Lease(job.job.id, "arm");
  AcceptTraceRequest request = MakeTestAccept(command, 100);
  request.frame = "rig_base_sensor_forces";
  request.registration_id = a2->id;
  absl::StatusOr<AcceptTraceResult> accepted = store_->AcceptTrace(request);
  ASSERT_TRUE(accepted.ok()) << accepted.status();
  absl::StatusOr<TraceFrameRecord> frame = store_->GetTraceFrame(accepted->trace_id);
  ASSERT_TRUE(frame.ok());
  EXPECT_EQ(frame->frame, "rig_base_sensor_forces");
  EXPECT_EQ(frame->registration_id, a2->id);
  CommandRecord second = Lease(job.job.id, "arm");
  absl::StatusOr<AcceptTraceResult> plain = store_->AcceptTrace(MakeTestAccept(second, 100));
  ASSERT_TRUE(plain.ok()) << plain.status();
  frame = store_->GetTraceFrame(plain->trace_id);
  ASSERT_TRUE(frame.ok());
  EXPECT_EQ(frame->frame, "object");
  EXPECT_EQ(frame->registration_id, 0);
  EXPECT_EQ(store_->GetTraceFrame(999).status().code(), absl::StatusCode::kNotFound);
}

// An import's implied command is written once, with its final state and
// owner (no insert-then-update), stored or refused; a job that takes no
// more imports refuses both before anything is written.
TEST_F(SqliteStoreTest, AnImportsCommandIsWrittenOnceWithItsFinalState) {
  CreatedJob job = Job(1);
  {
    // Counts every later UPDATE of a command row (a trigger in the file, seen by the store's writer).
    auto db = SqliteConnection::Open(path_, {});
    ASSERT_TRUE(db.ok()) << db.status();
    ASSERT_TRUE((*db)->Exec("CREATE TABLE command_updates (id INTEGER); "
                            "CREATE TRIGGER count_command_updates AFTER UPDATE ON commands "
                            "BEGIN INSERT INTO command_updates VALUES (NEW.id); END;").ok());
  }
  AcceptTraceRequest request;
  request.job_id = job.job.id;
  request.samples = MakeTestSamples(20, 3);
  request.fit = MakeTestFit(0.3);
  request.import = TraceImport{MakeTestCommand(0, 0), "hand-rig", std::string(64, 'a')};
  absl::StatusOr<AcceptTraceResult> stored = store_->AcceptTrace(request);
  ASSERT_TRUE(stored.ok()) << stored.status();
  const auto rejected = [&](int64_t job_id) {
    NewRejectedTrace r;
    r.job_id = job_id;
    r.rig_id = "hand-rig";
    r.check_name = "surface";
    r.message = "off the surface";
    r.encoded_samples = EncodeSamples(MakeTestSamples(20, 4));
    r.implied_command = MakeTestCommand(0, 0);
    r.import_sha256 = std::string(64, 'd');
    std::promise<absl::StatusOr<int64_t>> kept;
    store_->RecordRejectedTraceAsync(std::move(r), [&](absl::StatusOr<int64_t> id) { kept.set_value(id); });
    return kept.get_future().get();
  };
  absl::StatusOr<int64_t> refused = rejected(job.job.id);
  ASSERT_TRUE(refused.ok()) << refused.status();
  absl::StatusOr<RejectedTraceRecord> kept = store_->GetRejectedTrace(*refused);
  ASSERT_TRUE(kept.ok()) << kept.status();
  auto db = SqliteConnection::Open(path_, {});
  ASSERT_TRUE(db.ok());
  EXPECT_EQ(*(*db)->QueryInt("SELECT COUNT(*) FROM command_updates"), 0);
  for (const auto& [id, state] : {std::pair<int64_t, CommandState>{stored->command_id, CommandState::kDone},
                                  {kept->command_id, CommandState::kFailed}}) {
    absl::StatusOr<CommandRecord> command = store_->GetCommand(id);
    ASSERT_TRUE(command.ok()) << command.status();
    EXPECT_EQ(command->state, state);
    EXPECT_EQ(command->lease_owner, "hand-rig");
    EXPECT_EQ(command->attempt, 1);
  }
  // A hash that is not one is refused before anything is queued.
  const int64_t commands_before = *(*db)->QueryInt("SELECT COUNT(*) FROM commands");
  request.import->sha256 = std::string(64, 'B');
  absl::StatusOr<AcceptTraceResult> bad_hash = store_->AcceptTrace(request);
  EXPECT_EQ(bad_hash.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(bad_hash.status().message().find("import: sha256 must be 64 lower-case hex digits"), std::string::npos)
      << bad_hash.status();
  EXPECT_EQ(*(*db)->QueryInt("SELECT COUNT(*) FROM commands"), commands_before);
  // A cancelled job takes neither: nothing is written.
  ASSERT_TRUE(store_->UpdateJobState({job.job.id, JobState::kCancelled, {}}).ok());
  const int64_t commands = *(*db)->QueryInt("SELECT COUNT(*) FROM commands");
  request.import->sha256 = std::string(64, 'b');
  EXPECT_EQ(store_->AcceptTrace(request).status().code(), absl::StatusCode::kFailedPrecondition);
  EXPECT_EQ(rejected(job.job.id).status().code(), absl::StatusCode::kFailedPrecondition);
  EXPECT_EQ(*(*db)->QueryInt("SELECT COUNT(*) FROM commands"), commands);
}

// A refused import is kept once per file and job: importing the refused
// file again answers the stored rejected trace and writes nothing (no
// command, event or rejected trace).
TEST_F(SqliteStoreTest, ARefusedImportIsKeptOncePerFileAndJob) {
  CreatedJob job = Job(1);
  const auto keep = [&](NewRejectedTrace r) {
    std::promise<absl::StatusOr<int64_t>> kept;
    store_->RecordRejectedTraceAsync(std::move(r), [&](absl::StatusOr<int64_t> id) { kept.set_value(id); });
    return kept.get_future().get();
  };
  NewRejectedTrace import;
  import.job_id = job.job.id;
  import.rig_id = "hand-rig";
  import.check_name = "surface";
  import.message = "off the surface";
  import.encoded_samples = EncodeSamples(MakeTestSamples(20, 4));
  import.implied_command = MakeTestCommand(0, 0);
  import.import_sha256 = std::string(64, 'c');
  import.events.push_back(NewEvent{"import_rejected", "{}"});
  absl::StatusOr<int64_t> first = keep(import);
  ASSERT_TRUE(first.ok()) << first.status();
  const auto rejected_rows = [&] {
    auto db = SqliteConnection::Open(path_, {});
    return *(*db)->QueryInt("SELECT COUNT(*) FROM rejected_traces");
  };
  const std::map<std::string, int64_t> before = TableCounts();
  const int64_t rejected_before = rejected_rows();
  absl::StatusOr<int64_t> again = keep(import);
  ASSERT_TRUE(again.ok()) << again.status();
  EXPECT_EQ(*again, *first);
  EXPECT_EQ(TableCounts(), before) << "a repeat refused import wrote something";
  EXPECT_EQ(rejected_rows(), rejected_before);
  absl::StatusOr<RejectedTraceRecord> imported = store_->GetRejectedTrace(*first);
  ASSERT_TRUE(imported.ok()) << imported.status();
  EXPECT_EQ(imported->import_sha256, std::string(64, 'c'));
  import.import_sha256 = "not a hash";
  EXPECT_EQ(keep(import).status().code(), absl::StatusCode::kInvalidArgument);
}

// A rejected trace keeps the frame it was sent in and its registration (its
// samples are stored as sent); an import's is in the object's frame.
TEST_F(SqliteStoreTest, ARejectedTraceKeepsItsFrameAndRegistration) {
  CreatedJob job = Job(1);
  const auto keep = [&](NewRejectedTrace r) {
    std::promise<absl::StatusOr<int64_t>> kept;
    store_->RecordRejectedTraceAsync(std::move(r), [&](absl::StatusOr<int64_t> id) { kept.set_value(id); });
    return kept.get_future().get();
  };
  NewRejectedTrace import;
  import.job_id = job.job.id;
  import.rig_id = "hand-rig";
  import.check_name = "surface";
  import.message = "off the surface";
  import.encoded_samples = EncodeSamples(MakeTestSamples(20, 4));
  import.implied_command = MakeTestCommand(0, 0);
  import.import_sha256 = std::string(64, 'c');
  absl::StatusOr<int64_t> first = keep(import);
  ASSERT_TRUE(first.ok()) << first.status();

  absl::StatusOr<RigRegistrationRecord> reg = store_->AddRigRegistration({job.job.object_id, "arm", "{}"});
  ASSERT_TRUE(reg.ok()) << reg.status();
  CommandRecord command = Lease(job.job.id, "arm");
  NewRejectedTrace rig;
  rig.command_id = command.id;
  rig.job_id = job.job.id;
  rig.rig_id = "arm";
  rig.check_name = "offset";
  rig.message = "wrong frame?";
  rig.encoded_samples = EncodeSamples(MakeTestSamples(20, 5));
  rig.frame = "rig_base";
  rig.registration_id = reg->id;
  absl::StatusOr<int64_t> kept = keep(rig);
  ASSERT_TRUE(kept.ok()) << kept.status();
  absl::StatusOr<RejectedTraceRecord> read = store_->GetRejectedTrace(*kept);
  ASSERT_TRUE(read.ok()) << read.status();
  EXPECT_EQ(read->frame, "rig_base");
  EXPECT_EQ(read->registration_id, reg->id);
  EXPECT_EQ(read->samples.size(), 20u);
  absl::StatusOr<RejectedTraceRecord> imported = store_->GetRejectedTrace(*first);
  ASSERT_TRUE(imported.ok()) << imported.status();
  EXPECT_EQ(imported->frame, "object");
  EXPECT_EQ(imported->registration_id, 0);
  rig.registration_id = 0;  // a rig's frame without its registration
  EXPECT_EQ(keep(rig).status().code(), absl::StatusCode::kInvalidArgument);
}

// A bad frame is refused before the write is queued, naming the frame, and
// nothing is stored (the writer would fail it only after the caller had
// changed its plan in memory).
TEST_F(SqliteStoreTest, ABadTraceFrameIsRefusedBeforeTheWrite) {
  CreatedJob job = Job(2);
  absl::StatusOr<RigRegistrationRecord> reg = store_->AddRigRegistration({job.job.object_id, "arm", "{}"});
  ASSERT_TRUE(reg.ok()) << reg.status();
  CommandRecord command = Lease(job.job.id, "arm");
  const auto refused = [&](const std::string& frame, int64_t registration_id) {
    AcceptTraceRequest request = MakeTestAccept(command, 20);
    request.frame = frame;
    request.registration_id = registration_id;
    absl::Status s = store_->AcceptTrace(request).status();
    EXPECT_EQ(s.code(), absl::StatusCode::kInvalidArgument) << frame << " " << s;
    EXPECT_NE(s.message().find("frame:"), std::string_view::npos) << s;
  };
  refused("rig_tip", reg->id);       // not a frame
  refused("rig_base", 0);            // a rig's frame without its registration
  refused("object", reg->id);        // the object's frame with one
  absl::StatusOr<std::vector<TraceRecord>> traces = store_->ListTraces(job.job.id, false);
  ASSERT_TRUE(traces.ok()) << traces.status();
  EXPECT_TRUE(traces->empty());
}

}  // namespace
}  // namespace surfmap
