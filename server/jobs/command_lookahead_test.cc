#include "server/jobs/command_lookahead.h"

#include <string>

#include <gtest/gtest.h>

namespace surfmap {
namespace {

constexpr int64_t kLeaseMs = 60'000;

TEST(CommandLookaheadTest, CountsTheRigsThatAskedWithinTheirLeaseAtLeastOne) {
  CommandLookahead lookahead;
  EXPECT_EQ(lookahead.CommandsAhead(1'000'000), 1) << "no rig yet: one command for the first";
  lookahead.RigAsked("rig-a", 1'000'000, kLeaseMs);
  lookahead.RigAsked("rig-a", 1'010'000, kLeaseMs);  // the same rig twice counts once
  lookahead.RigAsked("rig-b", 1'020'000, kLeaseMs);
  EXPECT_EQ(lookahead.CommandsAhead(1'020'000), 2);
  lookahead.RigAsked("rig-c", 1'030'000, kLeaseMs);
  EXPECT_EQ(lookahead.CommandsAhead(1'030'000), 3);
  // rig-a last asked at 1'010'000: counted until a lease after that, then not.
  EXPECT_EQ(lookahead.CommandsAhead(1'070'000), 3);
  EXPECT_EQ(lookahead.CommandsAhead(1'070'001), 2);
  EXPECT_EQ(lookahead.CommandsAhead(2'000'000), 1) << "every rig gone quiet";
  // A clock that steps back does not forget a later ask.
  lookahead.RigAsked("rig-d", 3'000'000, kLeaseMs);
  lookahead.RigAsked("rig-e", 3'000'000, kLeaseMs);
  lookahead.RigAsked("rig-d", 2'999'000, kLeaseMs);
  EXPECT_EQ(lookahead.CommandsAhead(3'059'500), 2) << "rig-d asked at 3'000'000";
}

// A rig on a job with long leases may drag for longer than the default lease
// before it answers; it must still count then, or the job keeps one command
// too few and a second rig waits for the first to finish.
TEST(CommandLookaheadTest, ARigCountsForTheLeaseOfTheJobItAskedAbout) {
  CommandLookahead lookahead;
  lookahead.RigAsked("slow-rig", 0, /*lease_ms=*/600'000);
  lookahead.RigAsked("fast-rig", 0, kLeaseMs);
  lookahead.RigAsked("new-rig", 120'000, kLeaseMs);
  // fast-rig's lease has run out; slow-rig's has not.
  EXPECT_EQ(lookahead.CommandsAhead(120'000), 2);
  EXPECT_EQ(lookahead.CommandsAhead(180'001), 1) << "slow-rig alone";
  EXPECT_EQ(lookahead.CommandsAhead(600'001), 1) << "nobody: still one";
}

TEST(CommandLookaheadTest, InventedRigIdsCannotGrowItWithoutBound) {
  CommandLookahead lookahead;
  const std::size_t cap = CommandLookahead::kMaxCountedRigs;
  for (std::size_t i = 0; i < 3 * cap; ++i) lookahead.RigAsked("rig-" + std::to_string(i), 1'000, kLeaseMs);
  EXPECT_EQ(lookahead.CommandsAhead(1'000), static_cast<int>(cap));
  // Once they have gone quiet, new rigs are counted again.
  lookahead.RigAsked("late-a", 1'000 + kLeaseMs + 1, kLeaseMs);
  lookahead.RigAsked("late-b", 1'000 + kLeaseMs + 1, kLeaseMs);
  EXPECT_EQ(lookahead.CommandsAhead(1'000 + kLeaseMs + 1), 2);
}

}  // namespace
}  // namespace surfmap
