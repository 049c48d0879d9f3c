// SIGTERM / SIGINT: surfmapd drains and exits 0 within its shutdown deadline,
// even with a WatchJob stream open (a stream that would otherwise never end),
// and the data is there on the next start.
#include <atomic>
#include <csignal>
#include <thread>

#include "gtest/gtest.h"
#include "tests/support/job_helpers.h"
#include "tests/support/server_process.h"
#include "tests/support/status_matchers.h"

namespace surfmap::itest {
namespace {

using std::chrono::milliseconds;
using std::chrono::seconds;

void ShutDownWithAnOpenWatch(int signal) {
  constexpr double kDeadline = 3.0;
  ServerOptions options;
  options.config_json = R"({"shutdown_deadline_s": 3})";
  ITEST_ASSERT_OK_AND_ASSIGN(server, ServerProcess::Start(options));
  ITEST_ASSERT_OK_AND_ASSIGN(rig, MakeSceneRig("bottle"));
  Stubs stubs(server->channel());
  ITEST_ASSERT_OK_AND_ASSIGN(object, UploadSceneMesh(stubs, *rig));
  JobSpecOptions spec;
  spec.mode = pb::SAMPLING_MODE_UNIFORM;
  spec.finest_level = 0;
  ITEST_ASSERT_OK_AND_ASSIGN(job, CreateJob(stubs, MakeJobSpec(object.object_id(), spec)));

  std::atomic<int> updates{0};
  std::atomic<bool> ended{false};
  grpc::Status watch_status;
  std::thread watcher([&] {
    Stubs own(server->NewChannel());
    pb::WatchJobRequest request;
    request.set_job_id(job.job_id());
    auto context = Context(120);
    auto reader = own.jobs->WatchJob(context.get(), request);
    pb::JobUpdate update;
    while (reader->Read(&update)) ++updates;
    watch_status = reader->Finish();
    ended = true;
  });
  for (int i = 0; i < 1000 && updates == 0; ++i) std::this_thread::sleep_for(milliseconds(10));
  ASSERT_GT(updates.load(), 0) << "the watch stream never delivered the initial update";

  ITEST_ASSERT_OK(server->Signal(signal));
  auto exit = server->WaitForExit(milliseconds(static_cast<int>((kDeadline + 5) * 1000)));
  watcher.join();
  ASSERT_TRUE(exit.ok()) << exit.status();
  EXPECT_TRUE(exit->exited) << "killed by signal " << exit->signal << "\n" << server->LogTail();
  EXPECT_EQ(exit->code, 0) << server->LogTail();
  EXPECT_LE(exit->seconds, kDeadline + 2.0) << "shutdown took longer than the deadline (+2 s slack)";
  EXPECT_TRUE(ended.load());
  std::cout << "signal " << signal << ": exited " << exit->code << " after " << exit->seconds
            << " s; watch ended with " << Describe(watch_status) << "\n";

  // A clean restart on the same database sees the job.
  ITEST_ASSERT_OK(server->Restart());
  Stubs after(server->channel());
  ITEST_ASSERT_OK_AND_ASSIGN(again, GetJob(after, job.job_id()));
  EXPECT_EQ(again.state(), pb::JOB_STATE_RUNNING);
  auto stopped = server->Stop(seconds(15));
  ASSERT_TRUE(stopped.ok()) << stopped.status();
  EXPECT_EQ(stopped->code, 0);
}

TEST(GracefulShutdown, SigtermWithAnOpenWatchStreamExitsZeroWithinTheDeadline) { ShutDownWithAnOpenWatch(SIGTERM); }

TEST(GracefulShutdown, SigintExitsZeroToo) { ShutDownWithAnOpenWatch(SIGINT); }

}  // namespace
}  // namespace surfmap::itest
