#include "server/estimate/pair_groups.h"

#include <vector>

#include <gtest/gtest.h>

namespace surfmap {
namespace {

std::vector<double> Spaced(int n, double step) {
  std::vector<double> s;
  for (int i = 0; i < n; ++i) s.push_back(2.0 + step * i);
  return s;
}

TEST(PairsPerGroupTest, GroupsToTheSpacingAndLeavesThePaperRigAlone) {
  EXPECT_EQ(PairsPerGroup(Spaced(160, 0.1), 0.1), 1);    // 10 mm/s at 100 Hz
  EXPECT_EQ(PairsPerGroup(Spaced(160, 0.07), 0.1), 1);   // 1.43 rounds to 1
  EXPECT_EQ(PairsPerGroup(Spaced(320, 0.05), 0.1), 2);   // 5 mm/s at 100 Hz
  EXPECT_EQ(PairsPerGroup(Spaced(800, 0.02), 0.1), 5);   // 500 Hz
  EXPECT_EQ(PairsPerGroup(Spaced(1600, 0.01), 0.1), 10); // 1 kHz
  // The median spacing decides: slow ramps at both ends do not.
  std::vector<double> ramped = Spaced(800, 0.02);
  for (int i = 0; i < 100; ++i) ramped.insert(ramped.begin(), ramped.front() - 0.002);
  EXPECT_EQ(PairsPerGroup(ramped, 0.1), 5);
}

TEST(PairsPerGroupTest, DegenerateSeriesAreNotGrouped) {
  EXPECT_EQ(PairsPerGroup({}, 0.1), 1);
  EXPECT_EQ(PairsPerGroup(Spaced(1, 0.01), 0.1), 1);
  EXPECT_EQ(PairsPerGroup(Spaced(100, 0.01), 0.0), 1);         // grouping off
  EXPECT_EQ(PairsPerGroup(std::vector<double>(50, 3.0), 0.1), 1);  // no spacing
  EXPECT_EQ(PairsPerGroup(Spaced(6, 0.001), 0.1), 3);          // never fewer than two groups
}

TEST(AveragePairGroupsTest, MeansOfConsecutiveGroupsTheLastTakingTheRest) {
  const std::vector<double> s = Spaced(12, 0.02);
  std::vector<double> v;
  for (int i = 0; i < 12; ++i) v.push_back(i);
  const PairGroups g = AveragePairGroups(s, v, 5);
  ASSERT_EQ(g.values.size(), 2u);
  EXPECT_DOUBLE_EQ(g.values[0], 2.0);          // 0..4
  EXPECT_DOUBLE_EQ(g.values[1], 8.0);          // 5..11
  EXPECT_DOUBLE_EQ(g.s_mm[0], 2.0 + 0.02 * 2.0);
  EXPECT_DOUBLE_EQ(g.s_mm[1], 2.0 + 0.02 * 8.0);
  // One per group: the series itself.
  const PairGroups same = AveragePairGroups(s, v, 1);
  EXPECT_EQ(same.values, v);
  EXPECT_EQ(same.s_mm, s);
  // Fewer pairs than a group: one group of them all.
  EXPECT_EQ(AveragePairGroups(s, v, 50).values, std::vector<double>{5.5});
  EXPECT_TRUE(AveragePairGroups({}, {}, 5).values.empty());
}

TEST(ChangesOfPairsTest, AChangeBeforeGroupGIsBeforePairGk) {
  const std::vector<double> s = Spaced(100, 0.02);
  ChangePoint c;
  c.index = 7;
  c.s_mm = -1.0;
  c.statistic = 40.0;
  c.critical_value = 25.0;
  const std::vector<ChangePoint> pairs = ChangesOfPairs({c}, s, 5);
  ASSERT_EQ(pairs.size(), 1u);
  EXPECT_EQ(pairs[0].index, 35);
  EXPECT_DOUBLE_EQ(pairs[0].s_mm, 0.5 * (s[34] + s[35]));
  EXPECT_EQ(pairs[0].statistic, 40.0);
  EXPECT_EQ(pairs[0].critical_value, 25.0);
  EXPECT_EQ(ChangesOfPairs({c}, s, 1)[0].index, 7);
}

}  // namespace
}  // namespace surfmap
