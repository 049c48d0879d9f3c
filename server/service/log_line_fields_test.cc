#include "server/service/log_line_fields.h"

#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <spdlog/details/log_msg.h>
#include "server/base/log_text.h"
#include "server/service/json_log_formatter.h"

namespace surfmap {
namespace {

TEST(ParseLogLineTest, WordsAreTheMessageFieldsAreTyped) {
  LogLineFields p = ParseLogLine("job completed job_id=3 mu=0.125 rig=lab-arm-1 final=true levels=0..2");
  EXPECT_EQ(p.message, "job completed");
  ASSERT_EQ(p.fields.size(), 5u);
  EXPECT_EQ(p.fields[0].first, "job_id");
  EXPECT_EQ(p.fields[0].second, 3);
  EXPECT_EQ(p.fields[1].second, 0.125);
  EXPECT_EQ(p.fields[2].second, "lab-arm-1");
  EXPECT_EQ(p.fields[3].second, true);
  EXPECT_EQ(p.fields[4].second, "0..2");
}

TEST(ParseLogLineTest, QuotedValuesRoundTripThroughLogQuote) {
  const std::string reason = "reverse pass \"drifts\" 0.9 mm\nsee a=b";
  LogLineFields p = ParseLogLine("trace rejected reason=" + LogQuote(reason) + " command_id=17");
  EXPECT_EQ(p.message, "trace rejected");
  ASSERT_EQ(p.fields.size(), 2u);
  EXPECT_EQ(p.fields[0].second, reason);
  EXPECT_EQ(p.fields[1].second, 17);
}

TEST(ParseLogLineTest, NumbersJsonCannotHoldStayText) {
  LogLineFields p = ParseLogLine("x=nan y=inf z=12abc");
  ASSERT_EQ(p.fields.size(), 3u);
  EXPECT_EQ(p.fields[0].second, "nan");
  EXPECT_EQ(p.fields[1].second, "inf");
  EXPECT_EQ(p.fields[2].second, "12abc");
}

TEST(ParseLogLineTest, UnterminatedQuoteKeepsTheWholeLineAsMessage) {
  LogLineFields p = ParseLogLine("oops reason=\"no end");
  EXPECT_EQ(p.message, "oops reason=\"no end");
  EXPECT_TRUE(p.fields.empty());
}

TEST(JsonLogFormatterTest, FieldsAreKeysNotPackedIntoMsg) {
  JsonLogFormatter formatter;
  const std::string payload = "rig failure reported job_id=4 rig=r1 reason=" + LogQuote("arm \"stuck\"") + " msg=x";
  spdlog::details::log_msg msg("surfmapd", spdlog::level::info, payload);
  spdlog::memory_buf_t out;
  formatter.format(msg, out);
  const std::string text(out.data(), out.size());
  ASSERT_FALSE(text.empty());
  EXPECT_EQ(text.back(), '\n');
  const nlohmann::json j = nlohmann::json::parse(text);
  EXPECT_EQ(j["level"], "info");
  EXPECT_EQ(j["msg"], "rig failure reported");
  EXPECT_EQ(j["job_id"], 4);
  EXPECT_EQ(j["rig"], "r1");
  EXPECT_EQ(j["reason"], "arm \"stuck\"");
  EXPECT_EQ(j["msg_field"], "x");  // a field never replaces a fixed key
  EXPECT_TRUE(j["time_ms"].is_number_integer());
}

}  // namespace
}  // namespace surfmap
