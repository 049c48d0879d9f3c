// The default job through the real server: only object and property given,
// the server chooses the mode (BOUNDARY) and the levels from the mesh; a
// job's reach skips what a rig cannot touch; a rig's UNREACHABLE report is
// final at once while a TRANSIENT one is retried; a drag that crossed a
// material boundary comes back as pieces.
#include <cmath>

#include "gtest/gtest.h"
#include "tests/support/job_helpers.h"
#include "tests/support/server_process.h"
#include "tests/support/status_matchers.h"

namespace surfmap::itest {
namespace {

pb::JobSpec DefaultSpec(std::int64_t object_id) {
  pb::JobSpec spec;
  spec.set_object_id(object_id);
  spec.set_property(pb::PROPERTY_FRICTION);
  return spec;
}

const pb::PlanSite* FindSite(const pb::GetPlanResponse& plan, int vertex) {
  for (const pb::PlanSite& s : plan.sites()) {
    if (s.site().vertex() == vertex) return &s;
  }
  return nullptr;
}

TEST(DefaultJob, TheServerChoosesTheBoundaryModeAndLevelsFromTheMesh) {
  ITEST_ASSERT_OK_AND_ASSIGN(setup, StartServerWithScene("bottle"));
  ITEST_ASSERT_OK_AND_ASSIGN(job, CreateJob(*setup.stubs, DefaultSpec(setup.object_id)));
  const pb::JobSpec& spec = job.spec();
  EXPECT_EQ(spec.mode(), pb::SAMPLING_MODE_BOUNDARY);
  // The bottle's control edges are ~10-20 mm: ~1 mm map edges are 4 halvings
  // away (MapLevelFor), the plan two levels coarser.
  ASSERT_TRUE(spec.has_map_level());
  EXPECT_GE(spec.map_level(), 4);
  EXPECT_EQ(spec.finest_level(), spec.map_level() - 2);
  // Every control vertex is a first site: the bottle has 82.
  EXPECT_EQ(job.progress().pending() + job.progress().issued(), 82);
  ITEST_ASSERT_OK_AND_ASSIGN(map, [&]() -> absl::StatusOr<pb::GetMapResponse> {
    pb::GetMapRequest request;
    request.set_job_id(job.job_id());
    request.set_level(-1);
    pb::GetMapResponse response;
    grpc::Status status = setup.stubs->maps->GetMap(Context().get(), request, &response);
    if (!status.ok()) return absl::InternalError(status.error_message());
    return response;
  }());
  EXPECT_EQ(map.map().level(), spec.map_level());
}

TEST(DefaultJob, AThresholdOutsideAdaptiveIsRefusedAndUncertaintyNeedsABudget) {
  ITEST_ASSERT_OK_AND_ASSIGN(setup, StartServerWithScene("plate"));
  pb::JobSpec with_threshold = DefaultSpec(setup.object_id);
  with_threshold.set_threshold(4.0);
  absl::StatusOr<pb::JobInfo> refused = CreateJob(*setup.stubs, with_threshold);
  ASSERT_FALSE(refused.ok());
  EXPECT_NE(refused.status().message().find("threshold is read only by ADAPTIVE"), std::string::npos)
      << refused.status();
  pb::JobSpec uncertainty = DefaultSpec(setup.object_id);
  uncertainty.set_mode(pb::SAMPLING_MODE_UNCERTAINTY);
  absl::StatusOr<pb::JobInfo> no_budget = CreateJob(*setup.stubs, uncertainty);
  ASSERT_FALSE(no_budget.ok());
  EXPECT_NE(no_budget.status().message().find("budget"), std::string::npos) << no_budget.status();
}

TEST(DefaultJob, SitesOutsideTheReachAreSkippedWithTheReason) {
  ITEST_ASSERT_OK_AND_ASSIGN(setup, StartServerWithScene("bottle"));
  pb::JobSpec spec = DefaultSpec(setup.object_id);
  // A probe coming from +x that can tilt 60 degrees: the back of the bottle
  // (normals towards -x) is out of reach.
  spec.mutable_reach()->mutable_approach_direction()->set_x(1.0);
  spec.mutable_reach()->set_max_angle_deg(60.0);
  ITEST_ASSERT_OK_AND_ASSIGN(job, CreateJob(*setup.stubs, spec));
  EXPECT_DOUBLE_EQ(job.spec().reach().max_angle_deg(), 60.0);
  ITEST_ASSERT_OK_AND_ASSIGN(plan, GetPlan(*setup.stubs, job.job_id()));
  int skipped = 0, planned = 0;
  for (const pb::PlanSite& s : plan.sites()) {
    if (s.state() == pb::SITE_STATE_SKIPPED) {
      ++skipped;
      EXPECT_NE(s.failure_reason().find("unreachable"), std::string::npos) << s.failure_reason();
    } else {
      ++planned;
    }
  }
  // Normals within 60 degrees of +x cover about a quarter of a body of
  // revolution's side (cos 60 = 0.5: the band |phi| < 60 degrees is 1/3 of
  // the circumference, less the top and bottom caps).
  EXPECT_GT(skipped, 82 / 2) << "planned " << planned;
  EXPECT_GT(planned, 82 / 8) << "skipped " << skipped;
}

TEST(DefaultJob, UnreachableIsFinalAtOnceWhileTransientIsRetried) {
  ITEST_ASSERT_OK_AND_ASSIGN(setup, StartServerWithScene("plate"));
  ITEST_ASSERT_OK_AND_ASSIGN(job, CreateJob(*setup.stubs, DefaultSpec(setup.object_id)));
  auto report = [&](const pb::ProbeCommand& command, pb::FailureKind kind) -> absl::StatusOr<bool> {
    pb::ReportFailureRequest request;
    request.set_command_id(command.command_id());
    request.set_rig_id("rig-a");
    request.set_reason(kind == pb::FAILURE_KIND_UNREACHABLE ? "outside the workspace" : "lost contact");
    request.set_kind(kind);
    pb::ReportFailureResponse response;
    grpc::Status status = setup.stubs->probe->ReportFailure(Context().get(), request, &response);
    if (!status.ok()) return absl::InternalError(status.error_message());
    return response.will_retry();
  };
  ITEST_ASSERT_OK_AND_ASSIGN(first, LeaseOne(*setup.stubs, job.job_id(), "rig-a"));
  ITEST_ASSERT_OK_AND_ASSIGN(first_retried, report(first, pb::FAILURE_KIND_UNREACHABLE));
  EXPECT_FALSE(first_retried) << "an unreachable site must not be retried";
  ITEST_ASSERT_OK_AND_ASSIGN(second, LeaseOne(*setup.stubs, job.job_id(), "rig-a"));
  ITEST_ASSERT_OK_AND_ASSIGN(second_retried, report(second, pb::FAILURE_KIND_TRANSIENT));
  EXPECT_TRUE(second_retried) << "a transient failure is retried (max_retries 2)";

  ITEST_ASSERT_OK_AND_ASSIGN(plan, GetPlan(*setup.stubs, job.job_id()));
  const pb::PlanSite* gone = FindSite(plan, first.site().vertex());
  ASSERT_NE(gone, nullptr);
  EXPECT_EQ(gone->state(), pb::SITE_STATE_FAILED);
  EXPECT_NE(gone->failure_reason().find("outside the workspace"), std::string::npos) << gone->failure_reason();
  const pb::PlanSite* again = FindSite(plan, second.site().vertex());
  ASSERT_NE(again, nullptr);
  EXPECT_NE(again->state(), pb::SITE_STATE_FAILED);
}

// The default job decides each drag from the map as it stands when the
// command is issued (skipping coarse sites earlier drags covered), so the
// server keeps only as many commands issued as rigs ask for, not the whole
// coarse pass (server/jobs/command_lookahead.h); a restart restores exactly
// what was issued.
TEST(DefaultJob, CommandsAreIssuedAsRigsAskNotTheWholePassAtOnce) {
  ITEST_ASSERT_OK_AND_ASSIGN(setup, StartServerWithScene("plate"));
  ITEST_ASSERT_OK_AND_ASSIGN(job, CreateJob(*setup.stubs, DefaultSpec(setup.object_id)));
  EXPECT_EQ(job.progress().issued(), 1) << "no rig has asked yet: one command for the first";
  EXPECT_GT(job.progress().pending(), 10);

  ITEST_ASSERT_OK_AND_ASSIGN(a, LeaseOne(*setup.stubs, job.job_id(), "rig-a"));
  // rig-b asks while rig-a holds the only command: nothing yet, come back.
  pb::LeaseCommandRequest ask;
  ask.set_rig_id("rig-b");
  ask.set_job_id(job.job_id());
  pb::LeaseCommandResponse none;
  GRPC_ASSERT_OK(setup.stubs->probe->LeaseCommand(Context().get(), ask, &none));
  EXPECT_FALSE(none.has_command() && none.command().command_id() != 0);
  EXPECT_GT(none.retry_after().nanos() + none.retry_after().seconds(), 0);

  // rig-a's answer issues a command for each rig that asked.
  ITEST_ASSERT_OK_AND_ASSIGN(request, ExecuteOnRig(*setup.rig, a, "rig-a"));
  pb::SubmitTraceResponse accepted;
  GRPC_ASSERT_OK(setup.stubs->probe->SubmitTrace(Context().get(), request, &accepted));
  ITEST_ASSERT_OK_AND_ASSIGN(after, GetJob(*setup.stubs, job.job_id()));
  EXPECT_EQ(after.progress().issued(), 2);
  EXPECT_EQ(after.progress().measured(), 1);
  ITEST_ASSERT_OK_AND_ASSIGN(b, LeaseOne(*setup.stubs, job.job_id(), "rig-b", std::chrono::seconds(2)));
  ITEST_ASSERT_OK_AND_ASSIGN(a2, LeaseOne(*setup.stubs, job.job_id(), "rig-a", std::chrono::seconds(2)));
  EXPECT_NE(a2.command_id(), b.command_id());

  // A restart replays the journal to the same plan: the same commands issued.
  ITEST_ASSERT_OK_AND_ASSIGN(before, GetPlan(*setup.stubs, job.job_id()));
  ITEST_ASSERT_OK(setup.server->Kill());
  ITEST_ASSERT_OK(setup.server->Restart());
  Stubs stubs(setup.server->channel());
  ITEST_ASSERT_OK_AND_ASSIGN(restored, GetPlan(stubs, job.job_id()));
  EXPECT_EQ(restored.progress().issued(), before.progress().issued());
  EXPECT_EQ(restored.progress().pending(), before.progress().pending());
  EXPECT_EQ(restored.progress().measured(), 1);
}

TEST(DefaultJob, ADragAcrossABoundaryComesBackAsPieces) {
  ITEST_ASSERT_OK_AND_ASSIGN(setup, StartServerWithScene("plate"));
  ITEST_ASSERT_OK_AND_ASSIGN(job, CreateJob(*setup.stubs, DefaultSpec(setup.object_id)));
  // Measure commands until one drag found a change (the plate has four
  // materials meeting along lines; ~1 in 4 of its first drags crosses one).
  int measured = 0, with_change = 0;
  for (; measured < 60 && with_change == 0; ++measured) {
    ITEST_ASSERT_OK_AND_ASSIGN(command, LeaseOne(*setup.stubs, job.job_id(), "rig-a"));
    ITEST_ASSERT_OK_AND_ASSIGN(request, ExecuteOnRig(*setup.rig, command, "rig-a"));
    pb::SubmitTraceResponse response;
    GRPC_ASSERT_OK(setup.stubs->probe->SubmitTrace(Context().get(), request, &response));
    const pb::Fit& fit = response.sample().fit();
    ASSERT_EQ(fit.pieces_size(), fit.change_s_mm_size() + 1);
    // Pieces tile the data window in path order.
    EXPECT_NEAR(fit.pieces(0).start_mm(), fit.friction().window_start_mm(), 1e-9);
    EXPECT_NEAR(fit.pieces(fit.pieces_size() - 1).end_mm(), fit.friction().window_end_mm(), 1e-9);
    for (int i = 1; i < fit.pieces_size(); ++i) {
      EXPECT_TRUE(fit.pieces(i).starts_at_change());
      EXPECT_NEAR(fit.pieces(i).start_mm(), fit.pieces(i - 1).end_mm(), 1.0);
    }
    if (fit.change_s_mm_size() > 0) {
      ++with_change;
      // The plate's neighbouring materials differ by >= 0.05 in mu.
      EXPECT_GT(std::abs(fit.pieces(0).mu() - fit.pieces(1).mu()), 0.03);
    }
  }
  EXPECT_EQ(with_change, 1) << "no drag found a change in " << measured << " drags";
}

}  // namespace
}  // namespace surfmap::itest
