// SimulateDrag through the real server: a plate mapped by simulated rigs, then
// a drag played over the map's model. The rendered drag must read back (with
// the same estimator a measured drag goes through) as the map's friction
// where it ran, be the same for the same request, and bad requests must be
// refused naming what is wrong (the request's own fields before the map is
// built).
#include <algorithm>
#include <cmath>
#include <numeric>
#include <vector>

#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "server/base/testing/status_matchers.h"
#include "server/codec/trace_samples_proto.h"
#include "server/estimate/fit_trace.h"
#include "tests/support/job_helpers.h"
#include "tests/support/rig_fleet.h"
#include "tests/support/server_process.h"
#include "tests/support/status_matchers.h"

namespace surfmap::itest {
namespace {

using ::surfmap::status_matchers::StatusIs;
using ::testing::HasSubstr;

// The rendered drag has no sensor noise and a constant mu inside a region
// (the region map is sharp); what scatters a drag's friction is its texture's
// mean over the window: 0.027 of mu (standard deviation) per masonite drag,
// measured over 12 seeds. The mean of kRealisations drags has a standard
// error of 0.027 / sqrt(12) = 0.008; the tolerance is 2.5 of those. Another
// material of the plate is 0.05 (rubber) or 0.17 (wood) away.
constexpr int kRealisations = 12;
constexpr double kModelFrictionTolerance = 0.02;
// The map against the plate's true masonite (mu 0.25): the acceptance band of
// the map-quality scores (docs/method.md), a measured estimate.
constexpr double kTruthFrictionTolerance = 0.03;
constexpr double kMasoniteMu = 0.25;  // clients/sim/scenes/plate.json

absl::StatusOr<pb::SimulateDragResponse> SimulateDrag(Stubs& stubs, const pb::SimulateDragRequest& request) {
  pb::SimulateDragResponse response;
  grpc::Status status = stubs.maps->SimulateDrag(Context().get(), request, &response);
  if (!status.ok()) return FromGrpc(status, "SimulateDrag");
  return response;
}

absl::StatusOr<pb::MapValue> QueryOne(Stubs& stubs, std::int64_t job_id, double x, double y, double z) {
  pb::QueryMapRequest request;
  request.set_job_id(job_id);
  pb::Vec3* p = request.add_points();
  p->set_x(x);
  p->set_y(y);
  p->set_z(z);
  pb::QueryMapResponse response;
  grpc::Status status = stubs.maps->QueryMap(Context().get(), request, &response);
  if (!status.ok()) return FromGrpc(status, "QueryMap");
  if (response.values_size() != 1) return absl::InternalError("QueryMap: not one value");
  return response.values(0);
}

class SimulateDragTest : public ::testing::Test {
 protected:
  void SetUp() override {
    absl::StatusOr<SceneServer> setup = StartServerWithScene("plate");
    ASSERT_TRUE(setup.ok()) << setup.status();
    setup_ = std::move(*setup);
  }

  // A uniform job over the plate's level-0 sites, measured to the end.
  std::int64_t MapThePlate() {
    absl::StatusOr<pb::JobInfo> job = CreateJob(*setup_.stubs, UniformLevel0Spec(setup_.object_id));
    EXPECT_TRUE(job.ok()) << job.status();
    if (!job.ok()) return 0;
    RigFleetOptions options;
    options.rigs = 2;
    options.job_id = job->job_id();
    RigFleet fleet(setup_.server->address(), *setup_.rig, options);
    const RigFleetRecord record = fleet.Run();
    EXPECT_TRUE(record.rpc_errors.empty()) << record.rpc_errors.front();
    absl::StatusOr<pb::JobInfo> done =
        WaitForJobState(*setup_.stubs, job->job_id(), pb::JOB_STATE_COMPLETED, std::chrono::seconds(60));
    EXPECT_TRUE(done.ok()) << done.status();
    return job->job_id();
  }

  SceneServer setup_;
};

TEST_F(SimulateDragTest, ADragOverTheModelReadsBackAsTheMapsFrictionAndRepeatsExactly) {
  const std::int64_t job_id = MapThePlate();
  ASSERT_GT(job_id, 0);
  // The middle of the masonite square, seen from above.
  ITEST_ASSERT_OK_AND_ASSIGN(here, QueryOne(*setup_.stubs, job_id, 31.25, -8.0, 50.0));
  ASSERT_LT(std::abs(here.mu() - kMasoniteMu), kTruthFrictionTolerance) << "the map itself is off: " << here.mu();

  pb::SimulateDragRequest request;
  request.set_job_id(job_id);
  *request.mutable_position() = here.surface_point();
  request.mutable_direction()->set_y(1.0);  // 16 mm along +y stays on the masonite
  request.set_length_mm(16.0);
  request.set_seed(3);
  ITEST_ASSERT_OK_AND_ASSIGN(drag, SimulateDrag(*setup_.stubs, request));
  ASSERT_GT(drag.samples().t_size(), 100);
  EXPECT_EQ(drag.samples().t_size(), drag.mu_size());
  EXPECT_EQ(drag.samples().t_size(), drag.region_size());

  // Read back by the estimator a measured drag goes through, over several
  // texture realisations: one drag's friction carries the mean of its
  // roughness force over the window, and masonite's texture is strongly
  // correlated (AR(2) 1.61/-0.73, sigma 0.16 N at 5 N), so single drags
  // scatter by a few hundredths of mu around the model's value.
  std::vector<double> fitted;
  for (std::uint64_t seed = 1; seed <= kRealisations; ++seed) {
    request.set_seed(seed);
    ITEST_ASSERT_OK_AND_ASSIGN(one, SimulateDrag(*setup_.stubs, request));
    ITEST_ASSERT_OK_AND_ASSIGN(trace, DragTraceFromProto(one.samples()));
    ITEST_ASSERT_OK_AND_ASSIGN(fit, FitTrace(trace, FitOptions{}));
    fitted.push_back(fit.friction.mu);
  }
  const double mean = std::accumulate(fitted.begin(), fitted.end(), 0.0) / fitted.size();
  EXPECT_NEAR(mean, here.mu(), kModelFrictionTolerance) << "per realisation: " << ::testing::PrintToString(fitted);

  // The same request gives the same drag, sample for sample; another seed
  // gives another texture.
  request.set_seed(3);
  ITEST_ASSERT_OK_AND_ASSIGN(again, SimulateDrag(*setup_.stubs, request));
  ASSERT_EQ(again.samples().fx_size(), drag.samples().fx_size());
  for (int i = 0; i < drag.samples().fx_size(); ++i) {
    ASSERT_EQ(again.samples().fx(i), drag.samples().fx(i)) << "sample " << i;
    ASSERT_EQ(again.samples().fz(i), drag.samples().fz(i)) << "sample " << i;
  }
  request.set_seed(4);
  ITEST_ASSERT_OK_AND_ASSIGN(other, SimulateDrag(*setup_.stubs, request));
  bool differs = false;
  for (int i = 0; i < std::min(other.roughness_n_size(), drag.roughness_n_size()); ++i) {
    differs = differs || other.roughness_n(i) != drag.roughness_n(i);
  }
  EXPECT_TRUE(differs) << "seed 4 rendered the same texture as seed 3";
}

TEST_F(SimulateDragTest, BadRequestsAreRefusedNamingWhatIsWrong) {
  // Before any sample: nothing to render.
  ITEST_ASSERT_OK_AND_ASSIGN(empty_job, CreateJob(*setup_.stubs, UniformLevel0Spec(setup_.object_id)));
  pb::SimulateDragRequest request;
  request.set_job_id(empty_job.job_id());
  request.mutable_position()->set_z(5.0);
  request.mutable_direction()->set_x(1.0);
  absl::StatusOr<pb::SimulateDragResponse> no_data = SimulateDrag(*setup_.stubs, request);
  EXPECT_THAT(no_data.status(), StatusIs(absl::StatusCode::kFailedPrecondition, HasSubstr("no measured sample")));
  // The request's own fields are checked before the job and its map are
  // looked at: a bad field is named for a job with no data and for no job.
  request.set_length_mm(800.0);
  EXPECT_THAT(SimulateDrag(*setup_.stubs, request).status(),
              StatusIs(absl::StatusCode::kInvalidArgument, HasSubstr("length_mm")));
  request.set_job_id(987654);
  EXPECT_THAT(SimulateDrag(*setup_.stubs, request).status(),
              StatusIs(absl::StatusCode::kInvalidArgument, HasSubstr("length_mm")));
  request.set_length_mm(0.0);

  const std::int64_t job_id = MapThePlate();
  ASSERT_GT(job_id, 0);
  request.set_job_id(job_id);
  request.mutable_direction()->set_x(0.0);
  EXPECT_THAT(SimulateDrag(*setup_.stubs, request).status(),
              StatusIs(absl::StatusCode::kInvalidArgument, HasSubstr("direction")));
  request.mutable_direction()->set_x(1.0);
  request.set_length_mm(800.0);
  EXPECT_THAT(SimulateDrag(*setup_.stubs, request).status(),
              StatusIs(absl::StatusCode::kInvalidArgument, HasSubstr("length_mm")));
  request.set_length_mm(0.0);
  request.mutable_position()->set_z(80.0);  // far above the plate
  // The model's geometry decides (the renderer's contact distance).
  EXPECT_THAT(SimulateDrag(*setup_.stubs, request).status(),
              StatusIs(absl::StatusCode::kFailedPrecondition, HasSubstr("from the model surface")));
  request.set_job_id(987654);
  EXPECT_THAT(SimulateDrag(*setup_.stubs, request).status(), StatusIs(absl::StatusCode::kNotFound));
}

}  // namespace
}  // namespace surfmap::itest
