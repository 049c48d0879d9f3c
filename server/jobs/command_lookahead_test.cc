#include "server/jobs/command_lookahead.h"

#include <gtest/gtest.h>

namespace surfmap {
namespace {

TEST(CommandLookaheadTest, CountsTheRigsThatAskedWithinTheWindowAtLeastOne) {
  CommandLookahead lookahead(/*window_ms=*/60'000);
  EXPECT_EQ(lookahead.CommandsAhead(1'000'000), 1) << "no rig yet: one command for the first";
  lookahead.RigAsked("rig-a", 1'000'000);
  lookahead.RigAsked("rig-a", 1'010'000);  // the same rig twice counts once
  lookahead.RigAsked("rig-b", 1'020'000);
  EXPECT_EQ(lookahead.CommandsAhead(1'020'000), 2);
  lookahead.RigAsked("rig-c", 1'030'000);
  EXPECT_EQ(lookahead.CommandsAhead(1'030'000), 3);
  // rig-a last asked at 1'010'000: counted until 60 s after that, then not.
  EXPECT_EQ(lookahead.CommandsAhead(1'070'000), 3);
  EXPECT_EQ(lookahead.CommandsAhead(1'070'001), 2);
  EXPECT_EQ(lookahead.CommandsAhead(2'000'000), 1) << "every rig gone quiet";
  // A clock that steps back does not forget a later ask.
  lookahead.RigAsked("rig-d", 3'000'000);
  lookahead.RigAsked("rig-e", 3'000'000);
  lookahead.RigAsked("rig-d", 2'999'000);
  EXPECT_EQ(lookahead.CommandsAhead(3'059'500), 2) << "rig-d asked at 3'000'000";
}

}  // namespace
}  // namespace surfmap
