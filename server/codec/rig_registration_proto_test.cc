#include "server/codec/rig_registration_proto.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "server/base/testing/status_matchers.h"

namespace surfmap {
namespace {

namespace pb = ::surfmap::v1;
using ::testing::HasSubstr;
using status_matchers::IsOk;
using status_matchers::StatusIs;

TEST(TraceFrameProtoTest, EveryFrameRoundTrips) {
  for (TraceFrame frame : {TraceFrame::kObject, TraceFrame::kRigBase, TraceFrame::kRigBaseSensorForces}) {
    absl::StatusOr<TraceFrame> back = TraceFrameFromProto(TraceFrameToProto(frame));
    ASSERT_THAT(back, IsOk());
    EXPECT_EQ(*back, frame) << TraceFrameName(frame);
  }
  EXPECT_EQ(TraceFrameToProto(TraceFrame::kRigBase), pb::TRACE_FRAME_RIG_BASE);
  EXPECT_EQ(TraceFrameToProto(TraceFrame::kRigBaseSensorForces), pb::TRACE_FRAME_RIG_BASE_SENSOR_FORCES);
}

TEST(TraceFrameProtoTest, UnspecifiedIsTheObjectFrameAndUnknownIsRefused) {
  absl::StatusOr<TraceFrame> unspecified = TraceFrameFromProto(pb::TRACE_FRAME_UNSPECIFIED);
  ASSERT_THAT(unspecified, IsOk());
  EXPECT_EQ(*unspecified, TraceFrame::kObject);
  EXPECT_THAT(TraceFrameFromProto(static_cast<pb::TraceFrame>(77)),
              StatusIs(absl::StatusCode::kInvalidArgument, HasSubstr("frame: unknown value 77")));
}

TEST(RigRegistrationProtoTest, ReadsEveryFieldAndDefaultsTheSensorToTheBase) {
  pb::RigRegistration in;
  const Eigen::Quaterniond turn(Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitZ()));
  *in.mutable_object_pose()->mutable_rotation() = QuaternionToProto(turn);
  in.mutable_object_pose()->mutable_translation_mm()->set_x(10);
  in.mutable_object_pose()->mutable_translation_mm()->set_y(-20);
  in.mutable_object_pose()->mutable_translation_mm()->set_z(30);
  in.set_tip_radius_mm(2.5);
  absl::StatusOr<RigRegistration> r = RigRegistrationFromProto(in);
  ASSERT_THAT(r, IsOk());
  EXPECT_NEAR(r->object_rotation.angularDistance(turn), 0.0, 1e-12);
  EXPECT_EQ(r->object_translation_mm, Eigen::Vector3d(10, -20, 30));
  EXPECT_EQ(r->tip_radius_mm, 2.5);
  EXPECT_TRUE(r->sensor_rotation.isApprox(Eigen::Quaterniond::Identity()));

  const Eigen::Quaterniond sensor(Eigen::AngleAxisd(1.0, Eigen::Vector3d::UnitX()));
  *in.mutable_sensor_rotation() = QuaternionToProto(sensor);
  r = RigRegistrationFromProto(in);
  ASSERT_THAT(r, IsOk());
  EXPECT_NEAR(r->sensor_rotation.angularDistance(sensor), 0.0, 1e-12);

  in.set_tip_radius_mm(-1);
  EXPECT_THAT(RigRegistrationFromProto(in), StatusIs(absl::StatusCode::kInvalidArgument, HasSubstr("tip_radius_mm")));
}

}  // namespace
}  // namespace surfmap
