#include "server/jobs/trace_frame_check.h"

#include <cmath>
#include <random>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "server/base/testing/status_matchers.h"

namespace surfmap {
namespace {

using ::testing::HasSubstr;
using status_matchers::StatusIs;

// A drag on the plane z = 0 of the object's frame: 20 mm along x through the
// site (0, 0, 0), forward, pause, back; 5 N along +z, friction mu 0.3
// against the motion; seeded sensor noise.
DragTrace PlaneDrag() {
  std::mt19937 rng(17);
  std::normal_distribution<double> noise(0.0, 0.02);
  DragTrace trace;
  double t = 0;
  auto add = [&](double x, double direction, DragPhase phase) {
    const double friction = phase == DragPhase::kPause ? 0.0 : -0.3 * 5.0 * direction;
    trace.samples.push_back(
        {t, {x, 0.0, 0.0}, {friction + noise(rng), noise(rng), 5.0 + noise(rng)}, phase});
    t += 0.01;
  };
  for (int i = 0; i <= 200; ++i) add(-10.0 + 0.1 * i, 1.0, DragPhase::kForward);
  for (int i = 0; i < 50; ++i) add(10.0, 0.0, DragPhase::kPause);
  for (int i = 0; i <= 200; ++i) add(10.0 - 0.1 * i, -1.0, DragPhase::kReverse);
  return trace;
}

ProbeCommand Command() {
  ProbeCommand c;
  c.position = Eigen::Vector3d::Zero();
  c.normal = Eigen::Vector3d::UnitZ();
  c.drag_direction = Eigen::Vector3d::UnitX();
  return c;
}

RegisteredRig Rig() {
  RegisteredRig rig;
  rig.record.id = 7;
  rig.record.rig_name = "arm";
  rig.record.version = 2;
  rig.registration.object_rotation = Eigen::Quaterniond(Eigen::AngleAxisd(0.9, Eigen::Vector3d(1, 1, 0).normalized()));
  rig.registration.object_translation_mm = {420.0, -60.0, 110.0};
  rig.registration.sensor_rotation = Eigen::Quaterniond(Eigen::AngleAxisd(1.2, Eigen::Vector3d::UnitX()));
  return rig;
}

// The refusal the checks give `trace` read in `stated` with `rig`.
absl::Status Checked(const DragTrace& sent, TraceFrame stated, const RegisteredRig* rig) {
  const DragTrace object = rig ? TraceToObjectFrame(sent, stated, rig->registration) : sent;
  return CheckTraceAgainstCommand(object, Command(), TraceLimits{});
}

TEST(TraceFrameCheckTest, RigFramePositionsStatedAsObjectAreNamed) {
  const RegisteredRig rig = Rig();
  const DragTrace sent = TraceFromObjectFrame(PlaneDrag(), TraceFrame::kRigBase, rig.registration);
  const absl::Status refusal = Checked(sent, TraceFrame::kObject, &rig);
  ASSERT_THAT(refusal, StatusIs(absl::StatusCode::kInvalidArgument, HasSubstr("implausible trace: offset")));
  const absl::Status explained = ExplainWrongFrame(refusal, sent, TraceFrame::kObject, &rig, Command(), TraceLimits{});
  EXPECT_THAT(explained, StatusIs(absl::StatusCode::kInvalidArgument,
                                  HasSubstr("implausible trace: frame: the trace looks like it is in the rig's base "
                                            "frame, not in the object's frame as stated (TRACE_FRAME_OBJECT)")));
  EXPECT_THAT(explained, StatusIs(absl::StatusCode::kInvalidArgument, HasSubstr("registration 7 (rig 'arm', version 2)")));
  EXPECT_THAT(explained, StatusIs(absl::StatusCode::kInvalidArgument, HasSubstr("send it with frame = TRACE_FRAME_RIG_BASE")));
  EXPECT_EQ(PlausibilityCheckName(explained), "frame");
  // Stated rightly, the same trace passes the checks.
  EXPECT_TRUE(Checked(sent, TraceFrame::kRigBase, &rig).ok());
}

TEST(TraceFrameCheckTest, ObjectFrameDataStatedAsRigBaseIsNamed) {
  const RegisteredRig rig = Rig();
  const DragTrace sent = PlaneDrag();
  const absl::Status refusal = Checked(sent, TraceFrame::kRigBase, &rig);
  ASSERT_FALSE(refusal.ok());
  EXPECT_THAT(ExplainWrongFrame(refusal, sent, TraceFrame::kRigBase, &rig, Command(), TraceLimits{}),
              StatusIs(absl::StatusCode::kInvalidArgument,
                       HasSubstr("looks like it is in the object's frame, not in the rig's base frame as stated")));
}

// Positions right, forces in the sensor's frame stated as the base's: the
// fit's normal check refuses it; the force direction tells why.
TEST(TraceFrameCheckTest, SensorFramedForcesStatedAsBaseAreNamed) {
  const RegisteredRig rig = Rig();
  const DragTrace sent = TraceFromObjectFrame(PlaneDrag(), TraceFrame::kRigBaseSensorForces, rig.registration);
  EXPECT_TRUE(Checked(sent, TraceFrame::kRigBase, &rig).ok()) << "positions are where they belong";
  const absl::Status normal_refusal =
      absl::InvalidArgumentError("implausible trace: normal: the estimated surface normal is 69 deg from the commanded "
                                 "one; the limit is 30.0 deg: a trace in another frame?");
  EXPECT_THAT(ExplainWrongFrame(normal_refusal, sent, TraceFrame::kRigBase, &rig, Command(), TraceLimits{}),
              StatusIs(absl::StatusCode::kInvalidArgument,
                       HasSubstr("looks like it is in the rig's base frame with forces in the F/T sensor's frame")));
}

TEST(TraceFrameCheckTest, TheRegistrationAppliedBackwardsIsNamed) {
  const RegisteredRig rig = Rig();
  // base -> object applied to object data: q = R^T (p - t).
  const DragTrace sent = TraceToObjectFrame(PlaneDrag(), TraceFrame::kRigBase, rig.registration);
  const absl::Status refusal = Checked(sent, TraceFrame::kRigBase, &rig);
  ASSERT_FALSE(refusal.ok());
  EXPECT_THAT(ExplainWrongFrame(refusal, sent, TraceFrame::kRigBase, &rig, Command(), TraceLimits{}),
              StatusIs(absl::StatusCode::kInvalidArgument, HasSubstr("INVERSE of the registration")));
}

TEST(TraceFrameCheckTest, OtherFailuresKeepTheirMessage) {
  const RegisteredRig rig = Rig();
  // Far from the site in every frame.
  DragTrace far = PlaneDrag();
  for (DragSample& s : far.samples) s.position.x() += 2000.0;
  const absl::Status refusal = Checked(far, TraceFrame::kObject, &rig);
  ASSERT_FALSE(refusal.ok());
  EXPECT_EQ(ExplainWrongFrame(refusal, far, TraceFrame::kObject, &rig, Command(), TraceLimits{}), refusal);
  // In the right frame but refused for something else (here: a made-up
  // friction refusal): the frame is not what is wrong.
  const absl::Status friction = absl::InvalidArgumentError("implausible trace: friction: mu = -0.3");
  EXPECT_EQ(ExplainWrongFrame(friction, PlaneDrag(), TraceFrame::kObject, &rig, Command(), TraceLimits{}), friction);
  // Without a registration nothing can be said about frames.
  const DragTrace sent = TraceFromObjectFrame(PlaneDrag(), TraceFrame::kRigBase, rig.registration);
  const absl::Status unregistered = Checked(sent, TraceFrame::kObject, nullptr);
  EXPECT_EQ(ExplainWrongFrame(unregistered, sent, TraceFrame::kObject, nullptr, Command(), TraceLimits{}),
            unregistered);
  // A malformed-trace error is not a plausibility refusal: unchanged.
  const absl::Status malformed = absl::InvalidArgumentError("malformed trace: too few samples");
  EXPECT_EQ(ExplainWrongFrame(malformed, sent, TraceFrame::kObject, &rig, Command(), TraceLimits{}), malformed);
}

}  // namespace
}  // namespace surfmap
