#include "server/service/request_gate.h"

#include "gtest/gtest.h"

namespace surfmap {
namespace {

TEST(RequestGate, RoleOfFindsEveryTokenAndNothingElse) {
  RequestGate gate({{"reader-token-000000001", Role::kRead},
                    {"prober-token-000000001", Role::kProbe},
                    {"steerer-token-00000001", Role::kSteer}});
  Role role = Role::kRead;
  ASSERT_TRUE(gate.RoleOf("prober-token-000000001", &role));
  EXPECT_EQ(role, Role::kProbe);
  ASSERT_TRUE(gate.RoleOf("steerer-token-00000001", &role));
  EXPECT_EQ(role, Role::kSteer);
  ASSERT_TRUE(gate.RoleOf("reader-token-000000001", &role));
  EXPECT_EQ(role, Role::kRead);
  // Prefixes, extensions and near misses are not tokens (the digests differ).
  EXPECT_FALSE(gate.RoleOf("reader-token-00000000", &role));
  EXPECT_FALSE(gate.RoleOf("reader-token-0000000011", &role));
  EXPECT_FALSE(gate.RoleOf("reader-token-000000002", &role));
  EXPECT_FALSE(gate.RoleOf("", &role));
  EXPECT_FALSE(RequestGate().RoleOf("reader-token-000000001", &role));
}

}  // namespace
}  // namespace surfmap
