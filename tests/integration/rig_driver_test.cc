// `surfmap-rig --driver` with an external driver program, against the real
// server: the program is `surfmap-rig simulate-drag`, so the same job mapped
// with `--sim` on a twin server must give bit-identical traces (the JSON
// lines lose nothing).
#include <map>
#include <vector>

#include <nlohmann/json.hpp>
#include "absl/strings/str_cat.h"
#include "gtest/gtest.h"
#include "tests/support/child_process.h"
#include "tests/support/job_helpers.h"
#include "tests/support/server_process.h"
#include "tests/support/status_matchers.h"

#ifndef SURFMAP_RIG_PATH
#define SURFMAP_RIG_PATH "surfmap-rig"
#endif

namespace surfmap::itest {
namespace {

using std::chrono::seconds;

struct MappedJob {
  std::string rig_output;
  pb::JobInfo job;
  std::map<std::pair<int, int>, pb::TraceSamples> traces;  // by site
};

// A fresh server, the plate, an adaptive job, and one surfmap-rig process
// with `driver_args` until the job ends.
void MapPlate(const std::vector<std::string>& driver_args, MappedJob* out) {
  ITEST_ASSERT_OK_AND_ASSIGN(setup, StartServerWithScene("plate"));
  Stubs& stubs = *setup.stubs;
  JobSpecOptions spec;
  spec.finest_level = 1;
  spec.threshold = 2.0;
  ITEST_ASSERT_OK_AND_ASSIGN(job, CreateJob(stubs, MakeJobSpec(setup.object_id, spec)));
  std::vector<std::string> argv = {SURFMAP_RIG_PATH, "--server", setup.server->address(), "--job",
                                   absl::StrCat(job.job_id()), "--rig-id", "lab-arm", "--spool",
                                   setup.server->dir() + "/spool", "--quiet"};
  argv.insert(argv.end(), driver_args.begin(), driver_args.end());
  ITEST_ASSERT_OK_AND_ASSIGN(rig, ChildProcess::Start(argv, setup.server->dir() + "/rig.log"));
  ITEST_ASSERT_OK_AND_ASSIGN(exit_code, rig->Wait(seconds(120)));
  out->rig_output = rig->Output();
  ASSERT_EQ(exit_code, 0) << out->rig_output;
  ITEST_ASSERT_OK_AND_ASSIGN(done, WaitForJobState(stubs, job.job_id(), pb::JOB_STATE_COMPLETED, seconds(30)));
  out->job = done;
  ITEST_ASSERT_OK_AND_ASSIGN(samples, ListSamples(stubs, job.job_id()));
  for (const pb::Sample& sample : samples.samples()) {
    pb::GetTraceRequest get;
    get.set_trace_id(sample.trace_id());
    pb::GetTraceResponse trace;
    GRPC_ASSERT_OK(stubs.traces->GetTrace(Context().get(), get, &trace));
    out->traces[{sample.site().level(), sample.site().vertex()}] = trace.samples();
  }
}

TEST(RigDriver, AnExternalDriverProgramMapsThePlateAsTheBuiltInSimulatorDoes) {
  MappedJob external, built_in;
  MapPlate({"--driver", absl::StrCat(SURFMAP_RIG_PATH, " simulate-drag --sim plate")}, &external);
  ASSERT_FALSE(HasFatalFailure());
  MapPlate({"--sim", "plate"}, &built_in);
  ASSERT_FALSE(HasFatalFailure());

  EXPECT_NE(external.rig_output.find("lab-arm driver ready: surfmap-rig simulate-drag --sim plate"),
            std::string::npos)
      << external.rig_output;
  EXPECT_NE(external.rig_output.find("lab-arm driver exited with code 0"), std::string::npos) << external.rig_output;
  EXPECT_GT(external.job.progress().measured(), 99) << "the adaptive plan refined at level 1";
  EXPECT_EQ(external.job.progress().measured(), built_in.job.progress().measured());
  ASSERT_EQ(external.traces.size(), built_in.traces.size());
  for (const auto& [site, samples] : external.traces) {
    auto twin = built_in.traces.find(site);
    ASSERT_NE(twin, built_in.traces.end()) << "site L" << site.first << " v" << site.second;
    std::string difference;
    EXPECT_TRUE(SameSamples(samples, twin->second, &difference))
        << "site L" << site.first << " v" << site.second << ": " << difference;
  }
}

TEST(RigDriver, ADriverCannotStateARigFrameItsTraceLinesAreNotIn) {
  // The driver protocol's trace line is in the object's frame: --frame
  // rig_base with --driver would mislabel every trace, so it is refused
  // before anything is leased.
  ITEST_ASSERT_OK_AND_ASSIGN(setup, StartServerWithScene("plate"));
  ITEST_ASSERT_OK_AND_ASSIGN(job, CreateJob(*setup.stubs, UniformLevel0Spec(setup.object_id)));
  ITEST_ASSERT_OK_AND_ASSIGN(
      rig, ChildProcess::Start({SURFMAP_RIG_PATH, "--server", setup.server->address(), "--job",
                                absl::StrCat(job.job_id()), "--rig-id", "arm", "--spool", setup.server->dir() + "/spool",
                                "--quiet", "--frame", "rig_base", "--driver", "cat > /dev/null"},
                               setup.server->dir() + "/rig.log"));
  ITEST_ASSERT_OK_AND_ASSIGN(exit_code, rig->Wait(seconds(60)));
  const std::string output = rig->Output();
  EXPECT_EQ(exit_code, 2) << output;
  EXPECT_NE(output.find("--frame rig_base works with --sim only"), std::string::npos) << output;
  ITEST_ASSERT_OK_AND_ASSIGN(info, GetJob(*setup.stubs, job.job_id()));
  EXPECT_EQ(info.progress().leased(), 0) << "a command was leased";
}

TEST(RigDriver, ADriverThatBreaksTheProtocolStopsTheRigAndTheSiteGoesBack) {
  ITEST_ASSERT_OK_AND_ASSIGN(setup, StartServerWithScene("plate"));
  ITEST_ASSERT_OK_AND_ASSIGN(job, CreateJob(*setup.stubs, UniformLevel0Spec(setup.object_id)));
  // Says ready, then prints a debugging line instead of a trace.
  const std::string driver =
      R"(echo '{"type":"ready","protocol":1}'; read -r command; echo "measuring..."; cat > /dev/null)";
  ITEST_ASSERT_OK_AND_ASSIGN(
      rig, ChildProcess::Start({SURFMAP_RIG_PATH, "--server", setup.server->address(), "--job",
                                absl::StrCat(job.job_id()), "--rig-id", "buggy", "--spool",
                                setup.server->dir() + "/spool", "--quiet", "--driver", driver},
                               setup.server->dir() + "/rig.log"));
  ITEST_ASSERT_OK_AND_ASSIGN(exit_code, rig->Wait(seconds(60)));
  const std::string output = rig->Output();
  EXPECT_EQ(exit_code, 1) << output;
  EXPECT_NE(output.find("surfmap-rig: driver: INTERNAL: driver protocol: line is not JSON"), std::string::npos)
      << output;
  ITEST_ASSERT_OK_AND_ASSIGN(plan, GetPlan(*setup.stubs, job.job_id()));
  int measured = 0, failed_with_reason = 0;
  for (const pb::PlanSite& site : plan.sites()) {
    measured += site.state() == pb::SITE_STATE_MEASURED ? 1 : 0;
    if (site.failure_reason().find("driver protocol: line is not JSON") != std::string::npos) ++failed_with_reason;
  }
  EXPECT_EQ(measured, 0);
  EXPECT_EQ(failed_with_reason, 1) << "the rig reported the command it could not measure";
  EXPECT_EQ(plan.progress().leased(), 0) << "the failed command was given back, not left leased";
}

// What the driver says it could not do reaches the server with its kind and
// in its own words (the job's events record both).
TEST(RigDriver, TheDriversFailureKindsAndReasonsReachTheServer) {
  ITEST_ASSERT_OK_AND_ASSIGN(setup, StartServerWithScene("plate"));
  ITEST_ASSERT_OK_AND_ASSIGN(job, CreateJob(*setup.stubs, UniformLevel0Spec(setup.object_id)));
  const std::string driver = R"(echo '{"type":"ready","protocol":1}'
read -r first; id=$(printf '%s' "$first" | sed 's/.*"command_id":\([0-9]*\).*/\1/')
echo "{\"type\":\"failure\",\"command_id\":$id,\"kind\":\"unreachable\",\"reason\":\"outside the workspace box\"}"
read -r second; id=$(printf '%s' "$second" | sed 's/.*"command_id":\([0-9]*\).*/\1/')
echo "{\"type\":\"failure\",\"command_id\":$id,\"kind\":\"transient\",\"reason\":\"force ceiling 15 N exceeded\"}"
cat > /dev/null)";
  ITEST_ASSERT_OK_AND_ASSIGN(
      rig, ChildProcess::Start({SURFMAP_RIG_PATH, "--server", setup.server->address(), "--job",
                                absl::StrCat(job.job_id()), "--rig-id", "kinds", "--spool",
                                setup.server->dir() + "/spool", "--quiet", "--max-commands", "2", "--driver", driver},
                               setup.server->dir() + "/rig.log"));
  ITEST_ASSERT_OK_AND_ASSIGN(exit_code, rig->Wait(seconds(60)));
  const std::string output = rig->Output();
  ASSERT_EQ(exit_code, 0) << output;
  EXPECT_NE(output.find("kinds: 0 commands done, 2 failures"), std::string::npos) << output;
  pb::ListJobEventsRequest request;
  request.set_job_id(job.job_id());
  pb::ListJobEventsResponse events;
  GRPC_ASSERT_OK(setup.stubs->jobs->ListJobEvents(Context().get(), request, &events));
  std::vector<std::string> failures;
  for (const pb::JobEvent& event : events.events()) {
    if (event.kind() != "probe_failed") continue;
    const nlohmann::json detail = nlohmann::json::parse(event.detail_json());
    failures.push_back(absl::StrCat(detail.at("kind").get<std::string>(), " / ",
                                    detail.at("reason").get<std::string>(), " / ", detail.at("rig").get<std::string>()));
  }
  EXPECT_EQ(failures, (std::vector<std::string>{"unreachable / rig: outside the workspace box / kinds",
                                                "transient / rig: force ceiling 15 N exceeded / kinds"}));
}

}  // namespace
}  // namespace surfmap::itest
