#include "clients/rig/duration_text.h"

#include <gtest/gtest.h>

namespace surfmap::rig {
namespace {

TEST(ParseDurationSecondsTest, NumbersAndUnits) {
  EXPECT_DOUBLE_EQ(*ParseDurationSeconds("300"), 300.0);
  EXPECT_DOUBLE_EQ(*ParseDurationSeconds("0"), 0.0);
  EXPECT_DOUBLE_EQ(*ParseDurationSeconds("90s"), 90.0);
  EXPECT_DOUBLE_EQ(*ParseDurationSeconds("90 s"), 90.0);
  EXPECT_DOUBLE_EQ(*ParseDurationSeconds("5m"), 300.0);
  EXPECT_DOUBLE_EQ(*ParseDurationSeconds("5min"), 300.0);
  EXPECT_DOUBLE_EQ(*ParseDurationSeconds("1.5h"), 5400.0);
  EXPECT_DOUBLE_EQ(*ParseDurationSeconds("2.5"), 2.5);
}

TEST(ParseDurationSecondsTest, EverythingElseIsNamed) {
  for (const char* text : {"", "s", "five", "5 weeks", "-3", "nan", "inf", "5mins", "1e400"}) {
    auto parsed = ParseDurationSeconds(text);
    ASSERT_FALSE(parsed.ok()) << text;
    EXPECT_EQ(parsed.status().message(),
              std::string("'") + text + "' is not a duration (e.g. 300, 90s, 5min, 1.5h)");
  }
}

}  // namespace
}  // namespace surfmap::rig
