#include "clients/rig/probe_conversion.h"

#include <gtest/gtest.h>

namespace surfmap::rig {
namespace {

namespace pb = ::surfmap::v1;

pb::ProbeCommand ValidCommand() {
  pb::ProbeCommand c;
  c.set_command_id(42);
  c.mutable_position()->set_x(1);
  c.mutable_position()->set_y(2);
  c.mutable_position()->set_z(3);
  c.mutable_normal()->set_z(1);
  c.mutable_drag_direction()->set_y(1);
  return c;
}

TEST(ProbeRequestFromCommandTest, CopiesGeometryAndDefaultsZeroParameters) {
  pb::ProbeCommand c = ValidCommand();
  c.mutable_probe()->set_speed_mm_s(15);
  absl::StatusOr<ProbeRequest> r = ProbeRequestFromCommand(c);
  ASSERT_TRUE(r.ok()) << r.status();
  EXPECT_EQ(r->command_id, 42);
  EXPECT_EQ(r->position, Eigen::Vector3d(1, 2, 3));
  EXPECT_EQ(r->drag_direction, Eigen::Vector3d(0, 1, 0));
  EXPECT_DOUBLE_EQ(r->segment_length_mm, 20.0);
  EXPECT_DOUBLE_EQ(r->speed_mm_s, 15.0);
  EXPECT_DOUBLE_EQ(r->normal_force_n, 5.0);
}

TEST(ProbeRequestFromCommandTest, CarriesWhereTheCommandComesFrom) {
  pb::ProbeCommand c = ValidCommand();
  c.set_job_id(7);
  c.set_attempt(2);
  c.mutable_site()->set_level(1);
  c.mutable_site()->set_vertex(123);
  c.mutable_lease_deadline()->set_seconds(1795000060);
  c.mutable_lease_deadline()->set_nanos(250'000'000);
  absl::StatusOr<ProbeRequest> r = ProbeRequestFromCommand(c);
  ASSERT_TRUE(r.ok()) << r.status();
  EXPECT_EQ(r->job_id, 7);
  EXPECT_EQ(r->attempt, 2);
  EXPECT_EQ(r->site_level, 1);
  EXPECT_EQ(r->site_vertex, 123);
  EXPECT_EQ(r->lease_deadline_unix_ms, 1795000060250);
}

TEST(ProbeRequestFromCommandTest, RejectsAZeroNormalNamingTheCommand) {
  pb::ProbeCommand c = ValidCommand();
  c.clear_normal();
  absl::StatusOr<ProbeRequest> r = ProbeRequestFromCommand(c);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(r.status().message().find("command 42"), std::string_view::npos) << r.status();
}

}  // namespace
}  // namespace surfmap::rig
