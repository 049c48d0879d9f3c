#include "server/base/splitmix64.h"

#include <cstdint>

#include <gtest/gtest.h>

namespace surfmap {
namespace {

// The reference generator's first outputs for seed 0 (state advances by the
// golden-ratio increment, each output is SplitMix64Finalize of the state):
// the plan's issue order and the rigs' seeds depend on these exact values.
TEST(SplitMix64Test, MatchesTheReferenceSequenceFromSeedZero) {
  EXPECT_EQ(SplitMix64(0), 0xe220a8397b1dcdafULL);
  EXPECT_EQ(SplitMix64(0x9e3779b97f4a7c15ULL), 0x6e789e6aa1b965f4ULL);
}

TEST(SplitMix64Test, StepIsFinalizerOfIncrementedInput) {
  for (std::uint64_t x : {0ULL, 1ULL, 42ULL, ~0ULL}) {
    EXPECT_EQ(SplitMix64(x), SplitMix64Finalize(x + 0x9e3779b97f4a7c15ULL));
  }
  EXPECT_EQ(SplitMix64Finalize(0), 0u);  // the finaliser alone fixes zero
  EXPECT_NE(SplitMix64Finalize(1), SplitMix64Finalize(2));
}

}  // namespace
}  // namespace surfmap
