#include "server/base/utf8_text.h"

#include "gtest/gtest.h"

namespace surfmap {
namespace {

TEST(Utf8Text, CountsCharactersNotBytes) {
  EXPECT_EQ(Utf8Length("bottle"), 6u);
  EXPECT_EQ(Utf8Length("瓶"), 1u);             // 3 bytes
  EXPECT_EQ(Utf8Length("Glas\xc3\xa4"), 5u);   // ä
  EXPECT_EQ(Utf8Length("\xf0\x9f\x8d\xbe"), 1u);  // U+1F37E, 4 bytes
}

TEST(Utf8Text, RejectsMalformedSequences) {
  size_t bad = 99;
  EXPECT_FALSE(Utf8Length("ab\xff", &bad));
  EXPECT_EQ(bad, 2u);
  EXPECT_FALSE(Utf8Length("\xc0\xaf"));          // overlong '/'
  EXPECT_FALSE(Utf8Length("\xed\xa0\x80"));      // surrogate U+D800
  EXPECT_FALSE(Utf8Length("\xf4\x90\x80\x80"));  // above U+10FFFF
  EXPECT_FALSE(Utf8Length("\xe7\x93"));          // truncated
}

TEST(Utf8Text, ValidateNameNamesTheFieldAndTheLimit) {
  EXPECT_TRUE(ValidateName("name", std::string(200, 'n'), 1, 200).ok());
  std::string two_hundred_cjk;
  for (int i = 0; i < 200; ++i) two_hundred_cjk += "瓶";  // 600 bytes, 200 characters
  EXPECT_TRUE(ValidateName("name", two_hundred_cjk, 1, 200).ok());
  absl::Status too_long = ValidateName("name", two_hundred_cjk + "瓶", 1, 200);
  EXPECT_EQ(too_long.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(too_long.message(), "name must have 1..200 characters, got 201");
  EXPECT_EQ(ValidateName("name", "", 1, 200).message(), "name must have 1..200 characters, got 0");
  EXPECT_EQ(ValidateName("name", "a\xffz", 1, 200).message(), "name is not valid UTF-8 (byte 1 is 0xff)");
  EXPECT_EQ(ValidateName("rig_id", "rig\nrpc=Forged", 1, 100).message(),
            "rig_id contains the control character U+000A at character 4; names are one line of printable text");
}

TEST(Utf8Text, EscapeKeepsOneLineAndValidUtf8) {
  EXPECT_EQ(EscapeForLog("plain 瓶"), "plain 瓶");
  EXPECT_EQ(EscapeForLog("a\nb\r\tc\\"), "a\\nb\\r\\tc\\\\");
  EXPECT_EQ(EscapeForLog("x\x01y\x7f"), "x\\x01y\\x7f");
  EXPECT_EQ(EscapeForLog("bad\xff"), "bad\\xff");
  EXPECT_TRUE(Utf8Length(EscapeForLog("\xc0\xaf\xed\xa0\x80")).has_value());
}

}  // namespace
}  // namespace surfmap
