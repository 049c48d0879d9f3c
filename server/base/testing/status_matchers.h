// GoogleTest matchers for absl::Status and absl::StatusOr<T>:
//
//   using status_matchers::IsOk;  (namespace surfmap::status_matchers)
//   ASSERT_THAT(fit, IsOk());                              // stops the test, shows the status
//   EXPECT_THAT(parsed, StatusIs(absl::StatusCode::kInvalidArgument));
//   EXPECT_THAT(parsed, StatusIs(absl::StatusCode::kInvalidArgument, HasSubstr("line 3")));
//
// Why: EXPECT_TRUE(x.ok()) followed by *x dereferences an error when the
// expectation fails (undefined behaviour, not a test failure), and prints no
// status unless every call site remembers to stream it.
#pragma once

#include <ostream>
#include <string>

#include <gmock/gmock.h>
#include "absl/status/status.h"
#include "absl/status/statusor.h"

namespace surfmap::status_matchers {

inline const absl::Status& StatusOf(const absl::Status& status) { return status; }
template <typename T>
const absl::Status& StatusOf(const absl::StatusOr<T>& status_or) {
  return status_or.status();
}

MATCHER(IsOk, negation ? "is not OK" : "is OK") {
  const absl::Status& status = StatusOf(arg);
  if (!status.ok()) *result_listener << "status is " << status;
  return status.ok();
}

MATCHER_P(StatusIs, code, "has status code " + absl::StatusCodeToString(code)) {
  const absl::Status& status = StatusOf(arg);
  *result_listener << "status is " << status;
  return status.code() == code;
}

MATCHER_P2(StatusIs, code, message_matcher,
           "has status code " + absl::StatusCodeToString(code) + " and a message that " +
               ::testing::DescribeMatcher<std::string>(message_matcher)) {
  const absl::Status& status = StatusOf(arg);
  *result_listener << "status is " << status;
  return status.code() == code &&
         ::testing::ExplainMatchResult(message_matcher, std::string(status.message()), result_listener);
}

}  // namespace surfmap::status_matchers
