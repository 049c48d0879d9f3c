// surfmap-rig never loses a measured trace: a real surfmap-rig process against
// a real surfmapd that is killed (SIGKILL) and restarted three times while the
// rig works, and a rig that starts with traces left in its spool by a crash.
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <set>
#include <thread>

#include "absl/strings/str_cat.h"
#include "clients/rig/trace_spool.h"
#include "gtest/gtest.h"
#include "server/codec/trace_samples_proto.h"
#include "tests/support/child_process.h"
#include "tests/support/job_helpers.h"
#include "tests/support/server_process.h"
#include "tests/support/status_matchers.h"

#ifndef SURFMAP_RIG_PATH
#define SURFMAP_RIG_PATH "surfmap-rig"
#endif

namespace surfmap::itest {
namespace {

namespace fs = std::filesystem;
using std::chrono::milliseconds;
using std::chrono::seconds;
using Clock = std::chrono::steady_clock;

int Measured(ServerProcess& server, int64_t job_id) {
  Stubs stubs(server.channel());
  absl::StatusOr<pb::JobInfo> job = GetJob(stubs, job_id);
  return job.ok() ? job->progress().measured() : -1;
}

// Polls until the job has at least `count` measured sites (or `timeout`).
bool WaitForMeasured(ServerProcess& server, int64_t job_id, int count, milliseconds timeout) {
  const auto deadline = Clock::now() + timeout;
  while (Clock::now() < deadline) {
    if (Measured(server, job_id) >= count) return true;
    std::this_thread::sleep_for(milliseconds(5));
  }
  return false;
}

bool IsEmptyOrGone(const fs::path& dir) {
  std::error_code error;
  if (!fs::exists(dir, error)) return true;
  for (const auto& entry : fs::recursive_directory_iterator(dir, error)) {
    if (entry.is_regular_file()) return false;
  }
  return true;
}

TEST(RigSpool, ServerKilledThreeTimesWhileARigRunsLosesNothingAndStoresEachTraceOnce) {
  ServerOptions options;
  options.same_port_on_restart = true;  // the rig process keeps its --server address
  ITEST_ASSERT_OK_AND_ASSIGN(server, ServerProcess::Start(options));
  ITEST_ASSERT_OK_AND_ASSIGN(rig, MakeSceneRig("plate"));
  int64_t job_id = 0;
  int sites = 0;
  {
    Stubs stubs(server->channel());
    ITEST_ASSERT_OK_AND_ASSIGN(object, UploadSceneMesh(stubs, *rig));
    ITEST_ASSERT_OK_AND_ASSIGN(job, CreateJob(stubs, UniformLevel0Spec(object.object_id())));
    job_id = job.job_id();
    sites = job.progress().issued() + job.progress().pending();
  }
  ASSERT_GT(sites, 80) << "the plate's level 0 should give the rig work between the kills";
  const fs::path spool = fs::path(server->dir()) / "spool";
  ITEST_ASSERT_OK_AND_ASSIGN(
      rig_process, ChildProcess::Start({SURFMAP_RIG_PATH, "--server", server->address(), "--sim", "plate", "--job",
                                        absl::StrCat(job_id), "--rig-id", "restart-rig", "--spool", spool.string(),
                                        "--retry-for", "60", "--quiet"},
                                       server->dir() + "/rig.log"));

  // Three kills within 10 s, each while the rig is in the middle of the job:
  // the first once a fifth of it is measured, the next two once the rig has
  // measured a few more sites since the restart. The waits are for progress,
  // not a speed: the rig reconnects on its backoff (0.2 s doubling) and a
  // TSan-built server on a loaded machine needs seconds for the first
  // sites after a restart (a fifth of the job in 3 s missed there once).
  constexpr int kSitesBetweenKills = 3;
  Clock::time_point first_kill, last_kill;
  int target = sites / 5;
  for (int kill = 0; kill < 3; ++kill) {
    ASSERT_TRUE(WaitForMeasured(*server, job_id, target, seconds(60)))
        << "the rig made no progress after restart " << kill << "; rig output:\n" << rig_process->Output();
    ASSERT_TRUE(rig_process->running());
    ITEST_ASSERT_OK(server->Kill());
    if (kill == 0) first_kill = Clock::now();
    last_kill = Clock::now();
    std::this_thread::sleep_for(milliseconds(300));  // the rig meets a dead server
    ITEST_ASSERT_OK(server->Restart());
    ASSERT_TRUE(WaitForMeasured(*server, job_id, 0, seconds(60))) << "the restarted server does not answer GetJob";
    target = Measured(*server, job_id) + kSitesBetweenKills;
  }
  const double kill_span_s = std::chrono::duration<double>(last_kill - first_kill).count();
  EXPECT_LT(kill_span_s, 10.0) << "three kills should fall within 10 s";

  ITEST_ASSERT_OK_AND_ASSIGN(exit_code, rig_process->Wait(seconds(120)));
  const std::string output = rig_process->Output();
  ASSERT_EQ(exit_code, 0) << output;
  EXPECT_NE(output.find("restart-rig: server unavailable, retrying for "), std::string::npos)
      << "the rig should say it waits for the server:\n" << output;
  EXPECT_NE(output.find(absl::StrCat("restart-rig: ", sites, " commands done, 0 failures, 0 abandoned")),
            std::string::npos)
      << "every command answered by this rig exactly once (retries of stored traces count once):\n" << output;
  EXPECT_NE(output.find("job finished"), std::string::npos) << output;
  EXPECT_TRUE(IsEmptyOrGone(spool)) << "spool not empty: " << spool;

  Stubs stubs(server->channel());
  ITEST_ASSERT_OK_AND_ASSIGN(done, WaitForJobState(stubs, job_id, pb::JOB_STATE_COMPLETED, seconds(30)));
  EXPECT_EQ(done.progress().measured(), sites);
  EXPECT_EQ(done.progress().failed(), 0);
  ITEST_ASSERT_OK_AND_ASSIGN(samples, ListSamples(stubs, job_id));
  ASSERT_EQ(samples.samples_size(), sites) << "one stored trace per site";
  std::set<int64_t> commands, traces;
  std::set<std::pair<int, int>> site_set;
  for (const pb::Sample& sample : samples.samples()) {
    commands.insert(sample.command_id());
    traces.insert(sample.trace_id());
    site_set.insert({sample.site().level(), sample.site().vertex()});
    EXPECT_EQ(sample.rig_id(), "restart-rig");
  }
  EXPECT_EQ(static_cast<int>(commands.size()), sites) << "a command with two traces";
  EXPECT_EQ(static_cast<int>(traces.size()), sites);
  EXPECT_EQ(static_cast<int>(site_set.size()), sites) << "a site measured twice";
  std::cout << "rig through 3 server kills in " << kill_span_s << " s: " << output;
}

// A rig that crashed after spooling two traces starts again: the one whose
// lease it still holds is delivered (bit-exact), the one another rig answered
// meanwhile is refused and kept in rejected/ with the server's reason.
TEST(RigSpool, ARestartedRigResubmitsItsSpoolAndKeepsRefusalsWithTheirReason) {
  ITEST_ASSERT_OK_AND_ASSIGN(setup, StartServerWithScene("plate"));
  Stubs& stubs = *setup.stubs;
  ITEST_ASSERT_OK_AND_ASSIGN(job, CreateJob(stubs, UniformLevel0Spec(setup.object_id, 0, /*lease_s=*/60)));
  ITEST_ASSERT_OK_AND_ASSIGN(short_job, CreateJob(stubs, UniformLevel0Spec(setup.object_id, 0, /*lease_s=*/0.3)));

  // Command A: leased to the crashed rig, still its lease when it comes back.
  ITEST_ASSERT_OK_AND_ASSIGN(command_a, LeaseOne(stubs, job.job_id(), "crashed-rig"));
  ITEST_ASSERT_OK_AND_ASSIGN(request_a, ExecuteOnRig(*setup.rig, command_a, "crashed-rig"));
  // Command B: its lease expires and another rig measures it meanwhile.
  ITEST_ASSERT_OK_AND_ASSIGN(command_b, LeaseOne(stubs, short_job.job_id(), "crashed-rig"));
  ITEST_ASSERT_OK_AND_ASSIGN(request_b, ExecuteOnRig(*setup.rig, command_b, "crashed-rig"));
  std::this_thread::sleep_for(milliseconds(400));
  pb::ProbeCommand again;
  for (int i = 0; i < 100 && again.command_id() != command_b.command_id(); ++i) {
    ITEST_ASSERT_OK_AND_ASSIGN(leased, LeaseOne(stubs, short_job.job_id(), "other-rig"));
    again = leased;
  }
  ASSERT_EQ(again.command_id(), command_b.command_id()) << "command B was not re-issued";
  ITEST_ASSERT_OK_AND_ASSIGN(other_b, ExecuteOnRig(*setup.rig, again, "other-rig"));
  pb::SubmitTraceResponse answered;
  GRPC_ASSERT_OK(stubs.probe->SubmitTrace(Context().get(), other_b, &answered));

  // What the crashed rig had spooled.
  const fs::path spool_dir = fs::path(setup.server->dir()) / "spool";
  {
    ITEST_ASSERT_OK_AND_ASSIGN(spool, rig::TraceSpool::Open(spool_dir));
    int64_t measured_ms = 1;
    for (const auto* pair : {&command_a, &command_b}) {
      const pb::ProbeCommand& command = *pair;
      rig::SpoolHeader header;
      header.command_id = command.command_id();
      header.job_id = command.job_id();
      header.attempt = command.attempt();
      header.rig_id = "crashed-rig";
      header.measured_unix_ms = measured_ms++;
      ITEST_ASSERT_OK_AND_ASSIGN(trace, DragTraceFromProto(
                                            (&command == &command_a ? request_a : request_b).samples()));
      ITEST_ASSERT_OK(spool->Add(header, trace).status());
    }
  }  // the lock goes with the crashed process

  ITEST_ASSERT_OK_AND_ASSIGN(
      rig_process,
      ChildProcess::Start({SURFMAP_RIG_PATH, "--server", setup.server->address(), "--sim", "plate", "--job",
                           absl::StrCat(job.job_id()), "--rig-id", "crashed-rig", "--spool", spool_dir.string(),
                           "--max-commands", "1", "--quiet"},
                          setup.server->dir() + "/rig.log"));
  ITEST_ASSERT_OK_AND_ASSIGN(exit_code, rig_process->Wait(seconds(60)));
  const std::string output = rig_process->Output();
  ASSERT_EQ(exit_code, 0) << output;
  EXPECT_NE(output.find("crashed-rig: resubmitting 2 spooled traces from "), std::string::npos) << output;
  EXPECT_NE(output.find("1 spooled trace resubmitted; 1 trace rejected"), std::string::npos) << output;
  EXPECT_NE(output.find("refused trace(s) kept in " + (spool_dir / "rejected").string()), std::string::npos)
      << output;

  // A is stored as the crashed rig measured it.
  ITEST_ASSERT_OK_AND_ASSIGN(samples, ListSamples(stubs, job.job_id()));
  const pb::Sample* sample_a = nullptr;
  for (const pb::Sample& s : samples.samples()) {
    if (s.command_id() == command_a.command_id()) sample_a = &s;
  }
  ASSERT_NE(sample_a, nullptr) << "the spooled trace of command A was not stored";
  EXPECT_EQ(sample_a->rig_id(), "crashed-rig");
  pb::GetTraceRequest get;
  get.set_trace_id(sample_a->trace_id());
  pb::GetTraceResponse stored;
  GRPC_ASSERT_OK(stubs.traces->GetTrace(Context().get(), get, &stored));
  std::string difference;
  EXPECT_TRUE(SameSamples(stored.samples(), request_a.samples(), &difference)) << difference;

  // B is kept with the reason naming the rig that measured it.
  EXPECT_TRUE(rig::TraceSpool::Open(spool_dir).ok()) << "the rig released its spool";
  std::vector<fs::path> rejected;
  for (const auto& entry : fs::directory_iterator(spool_dir / "rejected")) rejected.push_back(entry.path());
  std::sort(rejected.begin(), rejected.end());
  ASSERT_EQ(rejected.size(), 2u);
  EXPECT_EQ(rejected[0].filename(), absl::StrCat("0000000000002-command-", command_b.command_id(), ".trace.csv"));
  std::ifstream reason_file(rejected[1]);
  std::string reason((std::istreambuf_iterator<char>(reason_file)), std::istreambuf_iterator<char>());
  EXPECT_EQ(reason.rfind("SubmitTrace: ALREADY_EXISTS: ", 0), 0u) << reason;
  EXPECT_NE(reason.find("other-rig"), std::string::npos) << reason;
  int pending = 0;
  for (const auto& entry : fs::directory_iterator(spool_dir)) pending += entry.is_regular_file() ? 1 : 0;
  EXPECT_EQ(pending, 0) << "nothing left waiting";
}

}  // namespace
}  // namespace surfmap::itest
