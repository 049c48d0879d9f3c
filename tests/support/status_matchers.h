// gtest helpers for absl and gRPC statuses in the integration tests:
// failures print the status text. The absl forms are shorthands for the one
// set of status matchers (server/base/testing/status_matchers.h: IsOk,
// StatusIs), not a second implementation; the gRPC forms print
// grpc::Status the way the harness describes it.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "absl/strings/ascii.h"

#include "gtest/gtest.h"
#include "server/base/testing/status_matchers.h"
#include "tests/support/surfmap_client.h"

#define ITEST_ASSERT_OK(expr) ASSERT_THAT((expr), ::surfmap::status_matchers::IsOk()) << #expr
#define ITEST_EXPECT_OK(expr) EXPECT_THAT((expr), ::surfmap::status_matchers::IsOk()) << #expr

// For absl::StatusOr<T>: assigns the value or fails the test.
#define ITEST_ASSERT_OK_AND_ASSIGN(lhs, expr)                                \
  auto lhs##_or = (expr);                                                    \
  ASSERT_THAT(lhs##_or, ::surfmap::status_matchers::IsOk()) << #expr;        \
  auto lhs = std::move(*lhs##_or)

#define GRPC_ASSERT_OK(expr)                                                     \
  do {                                                                           \
    const grpc::Status _itest_grpc = (expr);                                     \
    ASSERT_TRUE(_itest_grpc.ok()) << #expr << ": " << ::surfmap::itest::Describe(_itest_grpc); \
  } while (0)

#define GRPC_EXPECT_OK(expr)                                                     \
  do {                                                                           \
    const grpc::Status _itest_grpc = (expr);                                     \
    EXPECT_TRUE(_itest_grpc.ok()) << #expr << ": " << ::surfmap::itest::Describe(_itest_grpc); \
  } while (0)

namespace surfmap::itest {

// Whether an error message names the problem: holds one of `words`
// (case-insensitive). No words: any message will do.
inline bool MessageNames(const std::string& message, const std::vector<std::string>& words) {
  const std::string lower = absl::AsciiStrToLower(message);
  for (const std::string& word : words) {
    if (lower.find(absl::AsciiStrToLower(word)) != std::string::npos) return true;
  }
  return words.empty();
}

}  // namespace surfmap::itest
