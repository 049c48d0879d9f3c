#include "clients/rig/rig_frame_driver.h"

#include <cmath>

#include "gmock/gmock.h"
#include "gtest/gtest.h"

namespace surfmap::rig {
namespace {

using ::testing::HasSubstr;

// A driver recording in the object's frame: a straight drag along x at z = 0
// pressing along +z.
class ObjectFrameDriver : public RigDriver {
 public:
  absl::StatusOr<DragTrace> Execute(const ProbeRequest&) override {
    DragTrace trace;
    for (int i = 0; i <= 30; ++i) {
      trace.samples.push_back(DragSample{0.01 * i, {0.5 * i, 1.0, 0.0}, {-1.0, 0.0, 5.0}, DragPhase::kForward});
    }
    return trace;
  }
};

RigRegistration Registration() {
  RigRegistration r;
  r.object_rotation = Eigen::Quaterniond(Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()));
  r.object_translation_mm = {300, -20, 55};
  r.tip_radius_mm = 2;
  r.sensor_rotation = Eigen::Quaterniond(Eigen::AngleAxisd(1.1, Eigen::Vector3d::UnitZ()));
  return r;
}

TEST(RigFrameDriver, SendsTheTraceInTheRigFrameOfTheCommandsRegistration) {
  ObjectFrameDriver inner;
  int fetches = 0;
  RigFrameDriver driver(inner, TraceFrame::kRigBaseSensorForces, [&](std::int64_t id) -> absl::StatusOr<RigRegistration> {
    ++fetches;
    if (id != 9) return absl::NotFoundError("rig registration does not exist");
    return Registration();
  });
  ProbeRequest request;
  request.command_id = 4;
  request.rig_frame = RigFrameRequest{};
  request.rig_frame->registration_id = 9;
  absl::StatusOr<DragTrace> sent = driver.Execute(request);
  ASSERT_TRUE(sent.ok()) << sent.status();
  absl::StatusOr<DragTrace> object = inner.Execute(request);
  const DragTrace back = TraceToObjectFrame(*sent, TraceFrame::kRigBaseSensorForces, Registration());
  ASSERT_EQ(back.samples.size(), object->samples.size());
  for (size_t i = 0; i < back.samples.size(); ++i) {
    EXPECT_LT((back.samples[i].position - object->samples[i].position).norm(), 1e-9);
    EXPECT_LT((back.samples[i].force - object->samples[i].force).norm(), 1e-12);
  }
  EXPECT_GT((sent->samples[0].position - object->samples[0].position).norm(), 100.0);  // really in the base frame
  ASSERT_TRUE(driver.Execute(request).ok());
  EXPECT_EQ(fetches, 1) << "a registration is fetched once";

  request.rig_frame->registration_id = 10;
  const absl::Status missing = driver.Execute(request).status();
  EXPECT_EQ(missing.code(), absl::StatusCode::kInternal) << "the same for every command: the loop stops";
  EXPECT_THAT(std::string(missing.message()), HasSubstr("registration 10: rig registration does not exist (NOT_FOUND)"));
}

TEST(RigFrameDriver, AnUnreachableServerIsPassedOnForARetry) {
  ObjectFrameDriver inner;
  bool reachable = false;
  RigFrameDriver driver(inner, TraceFrame::kRigBase, [&](std::int64_t) -> absl::StatusOr<RigRegistration> {
    if (!reachable) return absl::UnavailableError("connection refused");
    return Registration();
  });
  ProbeRequest request;
  request.command_id = 4;
  request.rig_frame = RigFrameRequest{};
  request.rig_frame->registration_id = 9;
  EXPECT_EQ(driver.Execute(request).status().code(), absl::StatusCode::kUnavailable);
  reachable = true;
  EXPECT_TRUE(driver.Execute(request).ok()) << "a later command fetches again";
}

TEST(RigFrameDriver, ACommandWithoutItsRigFrameStopsTheRig) {
  ObjectFrameDriver inner;
  RigFrameDriver driver(inner, TraceFrame::kRigBase,
                        [](std::int64_t) -> absl::StatusOr<RigRegistration> { return Registration(); });
  ProbeRequest request;
  request.command_id = 4;
  const absl::Status refused = driver.Execute(request).status();
  EXPECT_EQ(refused.code(), absl::StatusCode::kInternal);
  EXPECT_THAT(std::string(refused.message()), HasSubstr("not registered to the job's object"));
}

}  // namespace
}  // namespace surfmap::rig
