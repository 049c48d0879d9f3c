#include "server/frames/rig_registration.h"

#include <cmath>
#include <limits>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace surfmap {
namespace {

using ::testing::HasSubstr;

constexpr std::array<double, 4> kIdentity = {1, 0, 0, 0};

TEST(RigRegistrationTest, AcceptsAValidRegistrationAndNormalises) {
  const double h = std::sqrt(0.5);
  absl::StatusOr<RigRegistration> r =
      MakeRigRegistration({h, 0, 0, h * (1 + 1e-7)}, {400, -50, 20}, 3.0, kIdentity);
  ASSERT_TRUE(r.ok()) << r.status();
  EXPECT_NEAR(r->object_rotation.norm(), 1.0, 1e-15);
  EXPECT_EQ(r->tip_radius_mm, 3.0);
}

TEST(RigRegistrationTest, RefusesBadValuesNamingTheField) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  struct Case {
    std::array<double, 4> rotation;
    Eigen::Vector3d translation;
    double radius;
    std::array<double, 4> sensor;
    const char* message;
  } cases[] = {
      {{1, 0, 0, 0.1}, {0, 0, 0}, 1, kIdentity, "object_pose.rotation is not a unit quaternion"},
      {{0, 0, 0, 0}, {0, 0, 0}, 1, kIdentity, "object_pose.rotation is not a unit quaternion"},
      {{nan, 0, 0, 0}, {0, 0, 0}, 1, kIdentity, "object_pose.rotation: a component is not finite"},
      {kIdentity, {0, nan, 0}, 1, kIdentity, "object_pose.translation_mm: a component is not finite"},
      {kIdentity, {2e4, 0, 0}, 1, kIdentity, "translation in metres or micrometres"},
      {kIdentity, {0, 0, 0}, -1, kIdentity, "tip_radius_mm must be in [0, 50] mm"},
      {kIdentity, {0, 0, 0}, 51, kIdentity, "tip_radius_mm must be in [0, 50] mm"},
      {kIdentity, {0, 0, 0}, nan, kIdentity, "tip_radius_mm"},
      {kIdentity, {0, 0, 0}, 1, {2, 0, 0, 0}, "sensor_rotation is not a unit quaternion"},
  };
  for (const Case& c : cases) {
    absl::StatusOr<RigRegistration> r = MakeRigRegistration(c.rotation, c.translation, c.radius, c.sensor);
    ASSERT_FALSE(r.ok()) << c.message;
    EXPECT_EQ(r.status().code(), absl::StatusCode::kInvalidArgument);
    EXPECT_THAT(std::string(r.status().message()), HasSubstr(c.message));
  }
}

TEST(RigRegistrationTest, JsonRoundTripIsExact) {
  absl::StatusOr<RigRegistration> r = MakeRigRegistration(
      {0.1, 0.7, -0.1, 0.0}, {1.0 / 3.0, 1e-7, -512.25}, 2.75, {0.0, 0.0, 0.0, 1.0});
  ASSERT_FALSE(r.ok());  // not unit: |q| = 0.714
  const Eigen::Quaterniond q = Eigen::Quaterniond(0.1, 0.7, -0.1, 0.3).normalized();
  r = MakeRigRegistration({q.w(), q.x(), q.y(), q.z()}, {1.0 / 3.0, 1e-7, -512.25}, 2.75, {0, 0, 0, 1});
  ASSERT_TRUE(r.ok()) << r.status();
  absl::StatusOr<RigRegistration> back = RigRegistrationFromJson(RigRegistrationToJson(*r));
  ASSERT_TRUE(back.ok()) << back.status();
  EXPECT_EQ(back->object_rotation.coeffs(), r->object_rotation.coeffs());
  EXPECT_EQ(back->object_translation_mm, r->object_translation_mm);
  EXPECT_EQ(back->tip_radius_mm, r->tip_radius_mm);
  EXPECT_EQ(back->sensor_rotation.coeffs(), r->sensor_rotation.coeffs());
}

TEST(RigRegistrationTest, JsonReaderNamesWhatIsMissing) {
  EXPECT_THAT(std::string(RigRegistrationFromJson("[]").status().message()), HasSubstr("not a JSON object"));
  EXPECT_THAT(std::string(RigRegistrationFromJson(R"({"object_rotation_wxyz": [1, 0, 0]})").status().message()),
              HasSubstr("object_rotation_wxyz must be an array of 4 numbers"));
  EXPECT_THAT(std::string(RigRegistrationFromJson(R"({"object_rotation_wxyz": [1, 0, 0, 0],
      "object_translation_mm": [0, 0, 0], "sensor_rotation_wxyz": [1, 0, 0, 0]})")
                              .status()
                              .message()),
              HasSubstr("tip_radius_mm must be a number"));
}

}  // namespace
}  // namespace surfmap
