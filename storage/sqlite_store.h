// SqliteStore: the Store on one SQLite file.
//
// Writes go through a GroupCommitWriter (one writer thread, one connection,
// group commit); reads use a pool of read-only connections (WAL lets them run
// beside the writer). Durability: WAL + synchronous=FULL, so a write is on disk
// (fsync of the WAL) before its caller or callback hears OK; this survives
// kill -9 and power loss (the latter as far as the disk honours fsync).
//
// Asynchronous calls: the callback runs on the writer thread, except when a
// request is rejected by validation before queuing, in which case it runs on
// the calling thread before the call returns.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string>

#include "absl/status/statusor.h"
#include "storage/group_commit_writer.h"
#include "storage/read_connection_pool.h"
#include "storage/store.h"
#include "storage/wal_checkpointer.h"

namespace surfmap {

struct SqliteStoreOptions {
  GroupCommitOptions writer;   // group commit on, batches of up to 256 writes
  int read_connections = 4;    // at most this many concurrent reads
  int bulk_read_connections = 2;  // of which at most this many large reads (samples, meshes)
  int busy_timeout_ms = 5000;  // waiting for another process's lock
  int page_size = 16384;       // for a new file; see SqliteOpenOptions
  // Time source for created/updated/received stamps (ms since the epoch).
  // Default: the system clock.
  std::function<int64_t()> clock;
  // Checkpoint the WAL on a background thread (wal_checkpointer.h) instead of
  // on the writer thread after a commit (SQLite's default).
  bool background_checkpoint = true;
  WalCheckpointOptions checkpoint;
};

class SqliteStore : public Store {
 public:
  // Opens or creates the file, applies pending schema migrations and starts
  // the writer. FailedPrecondition if the file's schema is newer than this
  // build; Unavailable if it cannot be opened.
  static absl::StatusOr<std::unique_ptr<SqliteStore>> Open(const std::string& path,
                                                           SqliteStoreOptions options = {});
  // Completes queued writes, then closes.
  ~SqliteStore() override;

  absl::StatusOr<int64_t> CreateObject(const NewObject& object) override;
  absl::StatusOr<ObjectRecord> GetObject(int64_t object_id, bool include_mesh) override;
  absl::StatusOr<std::vector<ObjectRecord>> ListObjects() override;

  absl::StatusOr<CreatedJob> CreateJob(const NewJob& job) override;
  absl::StatusOr<JobRecord> GetJob(int64_t job_id) override;
  absl::StatusOr<std::vector<JobRecord>> ListJobs(int64_t object_id) override;
  absl::StatusOr<std::vector<JobRecord>> ListActiveJobs() override;
  void UpdateJobStateAsync(JobStateChange change, JobCallback done) override;
  absl::StatusOr<PlanRecord> GetPlan(int64_t job_id) override;

  void LeaseNextCommandAsync(const LeaseRequest& request, LeaseCallback done) override;
  absl::StatusOr<CommandRecord> GetCommand(int64_t command_id) override;
  absl::StatusOr<std::vector<CommandRecord>> ListCommands(int64_t job_id) override;
  absl::StatusOr<LeasedCounts> CountLeasedCommands(int64_t job_id, int64_t now_unix_ms) override;

  void AcceptTraceAsync(AcceptTraceRequest request, AcceptTraceCallback done) override;
  void FailCommandAsync(FailCommandRequest request, FailCommandCallback done) override;
  absl::StatusOr<TraceRecord> GetTrace(int64_t trace_id, bool include_samples) override;
  absl::StatusOr<std::vector<TraceRecord>> ListTraces(int64_t job_id,
                                                      bool include_samples) override;
  absl::StatusOr<std::vector<TraceRecord>> ListTracesPage(int64_t job_id, int64_t after_trace_id, int limit,
                                                          bool include_samples) override;
  absl::StatusOr<JobActivity> GetJobActivity(int64_t job_id) override;
  absl::StatusOr<int64_t> FindImportedTrace(int64_t job_id, const std::string& sha256) override;

  absl::StatusOr<SampleRecord> ReadSample(int64_t trace_id, int32_t fit_version, bool include_samples) override;
  absl::StatusOr<std::vector<SampleRecord>> ReadJobSamples(int64_t job_id, int32_t fit_version) override;
  void SyncAsync(std::function<void(absl::Status)> done) override;

  void RecordRejectedTraceAsync(NewRejectedTrace trace, RejectedCallback done) override;
  absl::StatusOr<std::vector<RejectedTraceRecord>> ListRejectedTraces(int64_t job_id) override;
  absl::StatusOr<RejectedTraceRecord> GetRejectedTrace(int64_t id) override;

  absl::StatusOr<RigRegistrationRecord> AddRigRegistration(const NewRigRegistration& registration) override;
  absl::StatusOr<RigRegistrationRecord> GetRigRegistration(int64_t registration_id) override;
  absl::StatusOr<std::vector<RigRegistrationRecord>> ListRigRegistrations(int64_t object_id) override;
  absl::StatusOr<TraceFrameRecord> GetTraceFrame(int64_t trace_id) override;

  absl::StatusOr<FitRecord> GetFit(int64_t trace_id, int32_t version) override;
  absl::StatusOr<std::vector<FitRecord>> AddFits(const std::vector<TraceRefit>& fits) override;
  absl::StatusOr<std::vector<FitRecord>> ListFits(int64_t job_id, int32_t version) override;

  absl::StatusOr<std::vector<EventRecord>> ListEventsNewestFirst(int64_t job_id, int64_t before_id,
                                                                 int limit) override;
  absl::StatusOr<std::vector<EventRecord>> ListEvents(int64_t job_id, int64_t after_id,
                                                      int limit) override;

  // Transactions, writes and batch sizes so far (for benchmarks and tests).
  GroupCommitStats writer_stats() const { return writer_->stats(); }
  // Checkpoints run by the background checkpointer (0 if it is off).
  int64_t background_checkpoints() const {
    return checkpointer_ ? checkpointer_->checkpoints() : 0;
  }
  const std::string& path() const { return path_; }

 private:
  SqliteStore(std::string path, SqliteStoreOptions options,
              std::unique_ptr<WalCheckpointer> checkpointer,
              std::unique_ptr<GroupCommitWriter> writer);
  int64_t Now() const { return options_.clock(); }

  const std::string path_;
  const SqliteStoreOptions options_;
  // Declared before writer_: the writer (and its connection, which calls the
  // checkpointer's hook) is destroyed first.
  std::unique_ptr<WalCheckpointer> checkpointer_;
  std::unique_ptr<GroupCommitWriter> writer_;
  ReadConnectionPool readers_;
};

}  // namespace surfmap
